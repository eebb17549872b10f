#pragma once
// Running a loaded job (or resuming one): an EnsembleDriver with the observers the job asks for, then the
// run's files. In the output folder:
//   trajectory.csv    the samples (observers/sample_writer.hpp), streamed; none when output.every is 0
//   results.h5        output.format "hdf5" only, instead of trajectory.csv: the samples (observers/
//                     hdf5_sample_writer.hpp), then the tables and the run's facts (output/results_h5.hpp)
//   trajectories.csv  one row per trajectory, written at the end (header below)
//   summary.json      the run's facts (status, job, model, integrator, time grid, energy, counts, evaluations)
//   checkpoint.json   while the run is interrupted (checkpoint/checkpoint_saver.hpp)
// trajectories.csv header:
//   trajectory,status,step,t,q0,...,q<n-1>,p0,...,p<n-1>,H0,H,relative_energy_error,stop_step,stop_t,
//   stop_variable,message, then the observers' columns: max_abs_relative_energy_error, and with
//   /analysis/closest_return_after closest_return_distance,closest_return_t,closest_return_step.
// step, t, q, p and H are the final state's; stop_* say where a trajectory that stopped early (diverged, failed,
// inaccurate) stopped; empty cells are unknown or not applicable.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/progress_bar.hpp"
#include "nonsep/host/observers/runaway.hpp"
#include "nonsep/host/output/run_folder.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/trajectory.hpp"

namespace nonsep::host {

enum class DriverEnd;  // ensemble_driver.hpp

struct RunOptions {
  std::filesystem::path output_directory;        // created if missing
  ProgressStyle progress = ProgressStyle::none;  // on stderr (progress_bar.hpp; the caller checks for a terminal)
  double progress_interval = 10.0;               // seconds between progress lines (ProgressStyle::lines)
  // A distributed run's work unit: what its progress lines begin with (the rank and the unit) and when the rank's
  // next line is due, shared by its units (progress_bar.hpp). Empty and null for a whole run.
  std::string progress_label;
  std::shared_ptr<ProgressSchedule> progress_schedule;
  // Checked between chunks (a fraction of a second apart); when true the run stops with status "interrupted"
  // (set from a SIGINT handler).
  const std::atomic<bool>* stop_requested = nullptr;
  double chunk_seconds = run_chunk_seconds;  // the wall time of a chunk (EnsembleSetup::chunk_seconds)
  bool resume = false;                       // continue from output_directory/checkpoint.json (checkpoint_file.hpp)
  bool force = false;      // start over in a folder holding another job's results or a checkpoint (run_folder.hpp)
  unsigned threads = 0;    // worker threads; 0: all cores
  bool work_unit = false;  // a distributed run's unit (its folder's kind is "unit": run_folder.hpp)
  // A distributed run's work unit: the size of the whole ensemble it is part of, whose blocks (run_block_size_for)
  // the unit keeps, so that it counts evaluations as one process does. 0: the job's states are the whole.
  std::size_t whole_ensemble = 0;
  // Scheme "auto": what the pilots chose (study/scheme_choice.hpp to_json), written to summary.json as
  // "scheme_choice" with the run's own measurement against the tolerance, and into every checkpoint, from which a
  // resumed run takes it (checkpoint_file.hpp recorded_scheme_choice); null for a run without "auto".
  nlohmann::ordered_json scheme_choice;
  // The output folder, when the caller has taken it already (scheme "auto" takes it before its pilots, so that a
  // folder the run may not use is refused at once); null: run_job takes output_directory as `resume` and `force` say.
  std::shared_ptr<const RunFolder> folder;
};

// How many trajectories ended with each status.
struct StatusCounts {
  std::size_t completed = 0, diverged = 0, failed = 0, inaccurate = 0, interrupted = 0;
  std::size_t& operator[](TrajectoryStatus status);
};

struct RunOutcome {
  ExitStatus exit_status = ExitStatus::success;  // success, run_failed or interrupted
  // The run's status: interrupted, failed (the run as a whole, or a trajectory), diverged, inaccurate, completed:
  // the first that applies.
  TrajectoryStatus status = TrajectoryStatus::completed;
  std::string error;  // why the run as a whole failed (an output could not be written, ...); "" otherwise
  std::uint64_t steps_completed = 0;  // the last step any trajectory reached
  StatusCounts counts;
  std::vector<TrajectoryRecord> trajectories;              // one per trajectory, in job order
  std::optional<LargestEnergyError> largest_energy_error;  // over the steps where H was evaluated
  std::vector<std::optional<Runaway>> runaways;            // per trajectory: ran off with bounded energy (runaway.hpp)
  nlohmann::ordered_json summary;                          // what summary.json holds
  std::vector<std::string> notes;                          // for the user, not errors (e.g. "ran on one thread: ...")
  // Spread over work units (cluster/distributed_run.hpp): `trajectories` is empty (trajectories.csv has them).
  bool distributed = false;
};

// The status of a run whose driver ended with `end` and whose trajectories ended as `counts` say: the first of
// interrupted, failed (the run as a whole, or a trajectory), diverged, inaccurate, completed that applies. The
// one rule for a run's status: run_job and the merge of a distributed run's units both use it.
TrajectoryStatus run_status(DriverEnd end, const StatusCounts& counts);

// The exit status of a run that ended with `status`: success, interrupted or run_failed.
ExitStatus exit_status_of(TrajectoryStatus status);

// The output folder as `options` ask to use it (output/run_folder.hpp).
FolderUse folder_use(const RunOptions& options);

// The parameter sets of states whose sets are `set_of` (InitialStates::parameter_set, or a selection of its states
// in their order), for the driver (EnsembleSetup::parameter_sets): one per run of equal sets, with
// Job::parameter_set's parameters; empty without a sweep.
std::vector<ParameterSet> parameter_sets(const Job& job, const std::vector<std::size_t>& set_of);

// Runs `job`. Throws, before anything is computed: FolderInUse when the output folder is another run's or holds
// results this run may not replace (run_folder.hpp), OutputError when the folder or trajectory.csv cannot be
// created, and CheckpointError when asked to resume from a checkpoint that is missing, damaged or another job's.
// A resumed run ends with the same files, bit for bit, as an uninterrupted one (but summary.json's wall_seconds;
// its evaluation counts may exceed those by one gradient: the reused last gradient of the basic step is not in the
// checkpoint). Every failure after the start is reported in the outcome and in summary.json rather than thrown.
RunOutcome run_job(const LoadedJob& job, const RunOptions& options);

}  // namespace nonsep::host
