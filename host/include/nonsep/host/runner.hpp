#pragma once
// Running a loaded job, or resuming one (checkpoints below): samples stream to trajectory.csv, and summary.json
// is written at the end, whatever the end was.
//
// Blocks and threads. The trajectories are split into fixed blocks of `run_block_size` consecutive trajectories,
// whatever the number of threads; each block is one nonsep::PhaseSpaceBatch with its own Integrator (one plugin
// call per stage for the whole block). Blocks run on `RunOptions::threads` OpenMP threads, each thread with its
// own plugin instance (the ABI's contract: one instance per thread). The plugin evaluates every state on its own
// and the blocks do not depend on the thread count, so trajectory.csv and summary.json (except wall_seconds) are
// byte-identical for any number of threads. Rows of one sample are written in trajectory order.
//
// Stepping goes in chunks: from one event (a written sample, an energy evaluation, the end; at most
// `run_chunk_state_steps` state-steps) to the next, each block advances without per-step bookkeeping. When a
// block's chunk ends with a non-finite number or the plugin fails in it, the block goes back to its state at the
// chunk's start (integrator included) and redoes the chunk step by step with the checks below, so the numbers,
// evaluation counts and statuses are the same as if every step had been checked.
//
// Fused path: when the plugin provides integrate() (every SDK plugin does) and no per-step analysis is asked for
// (analysis.closest_return_after), a block's unchecked chunk is one call into the plugin, which runs the core's
// Integrator on its compiled-in model; the first-same-as-last gradient and the evaluation counts go in and come
// back into the block's Integrator, so replays, checkpoints and counts are those of the host path. A replay is
// always stepped by the host (RunOptions::fused).
//
// Per trajectory, at every step:
//   - a state with a non-finite q or p is retired with status "diverged" (step, t and the first non-finite
//     variable, e.g. "p[0]"); its "final" is its last finite state, which is also the last row written for it;
//   - when the plugin fails on the block (nonsep::ModelError), the step is redone state by state from the
//     previous step's copy, and only the states the plugin fails on are retired, with status "failed" and the
//     plugin's message.
// Removing a state from a block does not change the others' numbers.
//
// Energy: H (nonsep::EnergyEvaluator, needs the plugin's Hessians) is evaluated at step 0, at every written sample
// (output.every), every output.energy_every-th step when that is > 0, at the last step, and for the final state of
// a trajectory that stops early. relative_error_max_abs is the largest |H - H0| / |H0| over those steps only. A
// state whose H cannot be evaluated at one of those steps is retired as "failed". Without Hessians the H columns
// are empty, the energies null, and summary.energy.reason says why.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "nonsep/host/checkpoint.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host {

struct RunOptions {
  std::filesystem::path output_directory;  // where trajectory.csv and summary.json go; created if missing
  bool show_progress = false;              // draw a ProgressBar on stderr (the caller checks for a terminal)
  // Checked between chunks (at most 2^20 state-steps, a fraction of a second, apart); when true the run stops with status "interrupted" (set from a SIGINT handler).
  const std::atomic<bool>* stop_requested = nullptr;
  // Continue from output_directory/checkpoint.json (checkpoint.hpp) instead of starting at step 0.
  bool resume = false;
  unsigned threads = 0;  // worker threads; 0: all cores (omp_get_max_threads)
  // Run unchecked chunks through the plugin's own stepping loop (plugin_abi.h integrate, the fused path) when it
  // has one. Results are the same bit for bit either way (states, evaluation counts, files); false, or the
  // environment variable NONSEP_FUSED=0, steps through grad_T and grad_V as ABI version 1 plugins are (tests and
  // the benchmark compare the two).
  bool fused = true;
};

inline constexpr std::size_t run_block_size = 256;              // trajectories per block
inline constexpr std::uint64_t run_chunk_state_steps = 1 << 20;  // largest chunk: state-steps of all active states

struct RunOutcome {
  ExitStatus exit_status = ExitStatus::success;  // success, run_failed or interrupted
  // What summary.json holds, keys in the documented order, except "trajectories": its entries are written from
  // `trajectories` (summary_json.hpp) and not built as json values, which would cost more than the stepping on a
  // short ensemble.
  nlohmann::ordered_json summary;
  // summary.json's /trajectories as records, one per trajectory in job order (the initial states are the job's).
  // Empty for a study (run_study), whose summary has no trajectories.
  std::vector<TrajectoryRecord> trajectories;
};

// Runs `job`. Throws OutputError, before anything is
// computed, when the output folder or trajectory.csv cannot be created, and CheckpointError when asked to resume
// from a checkpoint that is missing, damaged or another job's.
//
// Checkpoints (job.checkpoint, checkpoint.hpp) are saved between chunks (checkpoint.every_steps ends a chunk), after flushing trajectory.csv, and when
// the run is interrupted (before the interrupted states' last rows, which a resumed run drops again); a run that
// ends otherwise removes checkpoint.json. A resumed run ends with the same final states, energies and
// trajectory.csv, bit for bit, as an uninterrupted one; its evaluation counts may exceed those by one gradient
// (the reused last gradient of the basic step is not in the checkpoint). Every failure after that is reported in
// the outcome (and in summary.json) rather than thrown; if even summary.json cannot be written the outcome says
// so in summary["error"] and exit_status is run_failed.
RunOutcome run_job(const LoadedJob& job, const RunOptions& options);

}  // namespace nonsep::host
