#pragma once
// A run's progress on stderr, in one of two styles:
//   bar    a one-line bar for a terminal: invisible for the first second (short runs print nothing), then redrawn at
//          most ten times a second, erased when finished;
//   lines  plain lines for a file (a batch log, Slurm's or mpirun's stderr): one line every `interval` seconds, the
//          first after one interval, never redrawn or erased:
//            nonsep: progress: t = 12.5 of 50 (25.0%), step 2500/10000, 32 active, max |dH/H0| 1.2e-09, ETA 31 s
// Both show the time reached, the fraction of the steps, the active trajectories, the largest relative energy
// error so far (when known) and the time left, estimated from the rate so far.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>

namespace nonsep::host {

enum class ProgressStyle { none, bar, lines };

class ProgressBar {
 public:
  // style: the caller's decision (bar when stderr is a terminal, lines otherwise, none with --quiet). total: steps of
  // the run, ending at t_end. interval: seconds between lines (style lines; > 0).
  ProgressBar(ProgressStyle style, std::uint64_t total_steps, double t_end, double interval_seconds = 10.0);
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;
  ~ProgressBar() { finish(); }

  // Called after each chunk; cheap when nothing is drawn (one clock read). Shows the largest relative energy error
  // of the ensemble so far when it is known.
  void update(std::uint64_t step, double t, std::size_t active_trajectories,
              std::optional<double> largest_energy_error = std::nullopt);
  // Erases the bar if it was drawn (lines stay).
  void finish();

 private:
  using Clock = std::chrono::steady_clock;
  ProgressStyle style_;
  bool drawn_ = false;
  std::uint64_t total_;
  double t_end_;
  Clock::duration interval_;
  Clock::time_point start_, next_draw_;
};

// True when file descriptor 2 is a terminal.
bool stderr_is_terminal();

}  // namespace nonsep::host
