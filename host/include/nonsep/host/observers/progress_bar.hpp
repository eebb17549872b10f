#pragma once
// A run's progress on stderr, in one of two styles:
//   bar    a one-line bar for a terminal: invisible for the first second (short runs print nothing), then redrawn at
//          most ten times a second, erased when finished;
//   lines  plain lines for a file (a batch log, Slurm's or mpirun's stderr): one line every `interval` seconds, the
//          first after one interval, never redrawn or erased:
//            nonsep: progress: t = 12.5 of 50 (25.0%), step 2500/10000, 32 active, max |dH/H0| 1.2e-09, ETA 31 s
// Both show the time reached, the fraction of the steps, the active trajectories, the largest relative energy
// error so far ("n/a" while H has been evaluated at step 0 only: H is evaluated at the samples, output.energy_every
// and the last step) and the time left, estimated from the rate of this process's steps (after a resume, the steps
// since the resumed one).
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

  // The stepping starts at `step` (a resumed run's step), now: the time left is estimated from the steps after it.
  void start_from(std::uint64_t step);
  // Called after each chunk; cheap when nothing is drawn (one clock read). Shows the largest relative energy error
  // of the ensemble so far when given: NaN shows as "n/a" (not known yet); nothing shows none.
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
  std::uint64_t start_step_ = 0;
  std::string label_;
  std::shared_ptr<ProgressSchedule> schedule_;
};

// The seconds left after `elapsed` seconds that took the steps from `start_step` to `step` of `total`, at that rate
// (0 before the first step).
double remaining_seconds(double elapsed, std::uint64_t start_step, std::uint64_t step, std::uint64_t total);
// ", max |dH/H0| 1.20e-09" (or "n/a" for NaN) after `separator` ("max |dH/H0|" prefixed by it); "" for nothing.
std::string energy_error_text(std::optional<double> largest, const char* separator);

// True when file descriptor 2 is a terminal.
bool stderr_is_terminal();

}  // namespace nonsep::host
