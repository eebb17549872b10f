#pragma once
// Running a loaded job, or resuming one: every initial state is stepped together as one nonsep::PhaseSpaceBatch
// (one plugin call per stage for the whole ensemble), samples stream to trajectory.csv, and summary.json is written
// at the end, whatever the end was.
//
// Per trajectory, after every step:
//   - a state with a non-finite q or p is retired with status "diverged" (step, t and the first non-finite
//     variable, e.g. "p[0]"); its "final" is its last finite state, which is also the last row written for it;
//   - when the plugin fails on the batch (nonsep::ModelError), the step is redone state by state from the
//     previous step's copy, and only the states the plugin fails on are retired, with status "failed" and the
//     plugin's message.
// Removing a state from the batch does not change the others: the plugin evaluates each state on its own, so the
// remaining states' numbers are the same bit for bit as in a run without the retired one.
//
// Energy: H (nonsep::EnergyEvaluator, needs the plugin's Hessians) is evaluated at every step; the summary's
// relative_error_max_abs is the largest |H - H0| / |H0| over every step, not only the sampled ones. Without
// Hessians the H columns are empty, the energies null, and summary.energy.reason says why.
#include <atomic>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host {

struct RunOptions {
  std::filesystem::path output_directory;  // where trajectory.csv and summary.json go; created if missing
  bool show_progress = false;              // draw a ProgressBar on stderr (the caller checks for a terminal)
  // Checked after every step; when true the run stops with status "interrupted" (set from a SIGINT handler).
  const std::atomic<bool>* stop_requested = nullptr;
  // Continue from output_directory/checkpoint.json (checkpoint.hpp) instead of starting at step 0.
  bool resume = false;
};

struct RunOutcome {
  ExitStatus exit_status = ExitStatus::success;  // success, run_failed or interrupted
  nlohmann::ordered_json summary;                // what summary.json holds, keys in the documented order
};

// Runs `job`. Throws OutputError, before anything is
// computed, when the output folder or trajectory.csv cannot be created, and CheckpointError when asked to resume
// from a checkpoint that is missing, damaged or another job's.
//
// Checkpoints (job.checkpoint, checkpoint.hpp) are saved between steps, after flushing trajectory.csv, and when
// the run is interrupted (before the interrupted states' last rows, which a resumed run drops again); a run that
// ends otherwise removes checkpoint.json. A resumed run ends with the same final states, energies and
// trajectory.csv, bit for bit, as an uninterrupted one; its evaluation counts may exceed those by one gradient
// (the reused last gradient of the basic step is not in the checkpoint). Every failure after that is reported in
// the outcome (and in summary.json) rather than thrown; if even summary.json cannot be written the outcome says
// so in summary["error"] and exit_status is run_failed.
RunOutcome run_job(const LoadedJob& job, const RunOptions& options);

}  // namespace nonsep::host
