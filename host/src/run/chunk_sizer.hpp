#pragma once
// How many steps a chunk takes: the stretch that every block steps between two meetings of the driver's threads
// (ensemble_driver.hpp). Each chunk aims at `seconds` of wall time, sized from the speed of the chunk before it:
//   - a cheap model meets rarely: a meeting costs a thread's wake-up on each side (tens of microseconds on a
//     virtual machine), which chunks of a fixed 2^20 state-steps (2.6 ms of paper1d's basic step) made 5% of a
//     two-thread run (docs/performance.md, figure 3);
//   - a costly one meets often enough that a SIGINT, a checkpoint or a progress line waits a fraction of a second
//     (2^20 state-steps of paper2d with Gauss 3 and four tangent vectors were 66 s).
// Where chunks end changes no number of a run (test_host_threads.cpp), so that sizing them from the clock leaves the
// outputs the same byte for byte.
#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace nonsep::host {

class ChunkSizer {
 public:
  // `seconds` >= 0; 0 makes every chunk one step.
  explicit ChunkSizer(double seconds) : seconds_(seconds) {}

  // The most steps the next chunk takes when `active` states are stepped (at least one).
  std::uint64_t longest(std::size_t active) const {
    return std::max<std::uint64_t>(1, state_steps_ / std::max<std::size_t>(1, active));
  }

  // A chunk of `steps` steps of `active` states took `elapsed` seconds: the next aims at `seconds` at that speed,
  // growing at most `growth` times a chunk (the first chunks, and a short one's clock, say little about the speed).
  void measured(std::uint64_t steps, std::size_t active, double elapsed) {
    const double done = static_cast<double>(steps) * static_cast<double>(std::max<std::size_t>(1, active));
    const double most = growth * done;
    const double wanted = elapsed > 0 ? done * (seconds_ / elapsed) : most;
    state_steps_ = static_cast<std::uint64_t>(std::clamp(wanted, 1.0, most));
  }

 private:
  static constexpr double growth = 8;
  double seconds_;
  std::uint64_t state_steps_ = 1;  // the first chunk: one step
};

}  // namespace nonsep::host
