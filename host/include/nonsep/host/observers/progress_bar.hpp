#pragma once
// A one-line progress bar on stderr for long runs. It stays invisible for the first second (short runs print
// nothing), then redraws at most ten times a second, and erases itself when finished.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace nonsep::host {

class ProgressBar {
 public:
  // enabled: the caller's decision (stderr is a terminal and --quiet was not given). total: steps of the run.
  ProgressBar(bool enabled, std::uint64_t total_steps);
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar() { finish(); }

  // Called after each chunk; cheap when nothing is drawn (one clock read). Shows the largest relative energy error
  // of the ensemble so far when it is known.
  void update(std::uint64_t step, double t, std::size_t active_trajectories,
              std::optional<double> largest_energy_error = std::nullopt);
  // Erases the bar if it was drawn.
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  bool enabled_;
  bool drawn_ = false;
  std::uint64_t total_;
  Clock::time_point start_, next_draw_;
};

// True when file descriptor 2 is a terminal.
bool stderr_is_terminal();

}  // namespace nonsep::host
