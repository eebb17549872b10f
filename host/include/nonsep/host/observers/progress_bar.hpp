#pragma once
// A run's progress on stderr, in one of two styles:
//   bar    a one-line bar for a terminal: invisible for the first second (short runs print nothing), then redrawn at
//          most ten times a second, erased when finished;
//   lines  plain lines for a file (a batch log, Slurm's or mpirun's stderr): one line every `interval` seconds, the
//          first after one interval, never redrawn or erased:
//            nonsep: progress: t = 12.5 of 50 (25.0%), step 2500/10000, 32 active, max |dH/H0| 1.2e-09, ETA 31 s
// Both show the time reached, the fraction of the steps, the active trajectories, the largest relative energy
// error so far (when known) and the time left, estimated from the rate so far.
//
// A rank of a distributed run runs work units one after another, each with a bar of its own: its lines begin with a
// label naming the rank and the unit, and the moment the next line is due (a ProgressSchedule) carries over from one
// unit to the next, so the rank writes one line every interval however short or long its units are:
//   nonsep: progress: rank 1 of 4, unit 000012 of 64: t = 12.5 of 50 (25.0%), step 2500/10000, 8 active, ...
// (everything after the label is the unit's).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace nonsep::host {

enum class ProgressStyle { none, bar, lines };

// When the next progress line is due: a bar's own, or shared by the bars of successive runs (a rank's work units).
struct ProgressSchedule {
  std::chrono::steady_clock::time_point next_line;
};

class ProgressBar {
 public:
  // style: the caller's decision (bar when stderr is a terminal, lines otherwise, none with --quiet). total: steps of
  // the run, ending at t_end. interval: seconds between lines (style lines; > 0). label: the start of each line
  // (style lines), none when empty. schedule: when the next line is due, kept across bars; null: the first line
  // after one interval from now.
  ProgressBar(ProgressStyle style, std::uint64_t total_steps, double t_end, double interval_seconds = 10.0,
              std::string label = {}, std::shared_ptr<ProgressSchedule> schedule = nullptr);
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
  Clock::time_point start_;
  std::string label_;
  std::shared_ptr<ProgressSchedule> schedule_;
};

// True when file descriptor 2 is a terminal.
bool stderr_is_terminal();

}  // namespace nonsep::host
