#include "nonsep/host/run/run_job.hpp"

#include <chrono>
#include <optional>

#include "nonsep/host/checkpoint.hpp"
#include "nonsep/host/observers/checkpoint_saver.hpp"
#include "nonsep/host/observers/closest_return.hpp"
#include "nonsep/host/observers/progress.hpp"
#include "nonsep/host/observers/sample_writer.hpp"
#include "nonsep/host/output/files.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "run/run_files.hpp"

namespace nonsep::host {

std::size_t& StatusCounts::operator[](TrajectoryStatus status) {
  switch (status) {
    case TrajectoryStatus::completed: return completed;
    case TrajectoryStatus::diverged: return diverged;
    case TrajectoryStatus::failed: return failed;
    case TrajectoryStatus::inaccurate: return inaccurate;
    default: return interrupted;
  }
}

namespace {

TrajectoryStatus run_status(DriverEnd end, const StatusCounts& counts) {
  if (end == DriverEnd::interrupted) return TrajectoryStatus::interrupted;
  if (end == DriverEnd::failed || counts.failed > 0) return TrajectoryStatus::failed;
  if (counts.diverged > 0) return TrajectoryStatus::diverged;
  if (counts.inaccurate > 0) return TrajectoryStatus::inaccurate;
  return TrajectoryStatus::completed;
}

ExitStatus exit_status_of(TrajectoryStatus status) {
  if (status == TrajectoryStatus::completed) return ExitStatus::success;
  if (status == TrajectoryStatus::interrupted) return ExitStatus::interrupted;
  return ExitStatus::run_failed;
}

}  // namespace

FolderUse folder_use(const RunOptions& options) {
  return options.resume ? FolderUse::resume : options.force ? FolderUse::force : FolderUse::fresh;
}

RunOutcome run_job(const LoadedJob& loaded, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Job& job = loaded.job;
  const SingleRun& run = job.run();
  const std::filesystem::path& directory = options.output_directory;
  const RunFolder folder(directory, "run", job.file, folder_use(options));
  std::optional<Checkpoint> checkpoint;
  if (options.resume) checkpoint = load_checkpoint(directory / checkpoint_file_name, loaded);

  EnsembleDriver driver(loaded.plugin, loaded.model,
                        {run.integrator, run.time, job.initial.dimension, job.initial.q, job.initial.p, options.threads,
                         options.stop_requested});
  const std::size_t count = job.initial.count;
  EnergyErrorObserver energy(count, driver.energy_available() ? run.energy_every : 0,
                             run.analysis.max_relative_energy_error);
  std::optional<ClosestReturnObserver> closest;
  if (run.analysis.closest_return_after)
    closest.emplace(*run.analysis.closest_return_after, job.initial.dimension, job.initial.q, job.initial.p);
  std::optional<SampleWriter> samples;
  if (run.every > 0) {
    samples.emplace(directory / SampleWriter::file_name, job.initial.dimension, count, run.every, driver.time(),
                    options.resume);
  } else {
    std::error_code ignored;
    std::filesystem::remove(directory / SampleWriter::file_name, ignored);  // an earlier run's would mislead
  }
  std::vector<Observer*> observers{&energy};
  if (closest) observers.push_back(&*closest);
  if (samples) observers.push_back(&*samples);
  CheckpointSaver saver(directory / checkpoint_file_name, job_fingerprint(loaded), run.checkpoint, driver, observers);
  ProgressObserver progress(options.show_progress, driver, &energy);
  for (Observer* observer : observers) driver.add_observer(*observer);
  driver.add_observer(saver);
  driver.add_observer(progress);
  if (checkpoint) {
    driver.restore(std::move(checkpoint->driver));
    for (Observer* observer : observers)
      if (const std::string name = observer->name(); !name.empty()) {
        if (!checkpoint->observers.contains(name))
          throw CheckpointError((directory / checkpoint_file_name).string() + " is damaged (no state for " + name +
                                ")");
        observer->restore(checkpoint->observers[name]);
      }
  }

  const DriverEnd end = driver.run();
  RunOutcome outcome;
  outcome.error = driver.error();
  outcome.steps_completed = driver.steps_completed();
  outcome.trajectories = driver.records();
  for (const TrajectoryRecord& record : outcome.trajectories) ++outcome.counts[record.status];
  outcome.status = run_status(end, outcome.counts);
  outcome.exit_status = exit_status_of(outcome.status);
  outcome.largest_energy_error = energy.largest();
  if (!loaded.plugin.thread_safe() && options.threads != 1)
    outcome.notes.push_back("ran on one thread: the plugin '" + loaded.plugin.name() +
                            "' declares \"thread_safe\": false (plugin_abi.h)");
  const RunFacts facts{loaded, directory, driver, outcome, run.every > 0,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  outcome.summary = run_summary(facts);
  const auto fail = [&](const OutputError& error) {
    outcome.error = (outcome.error.empty() ? "" : outcome.error + "; ") + error.what();
    outcome.summary["error"] = outcome.error;
    if (outcome.exit_status == ExitStatus::success) outcome.exit_status = ExitStatus::run_failed;
    if (outcome.status == TrajectoryStatus::completed) outcome.status = TrajectoryStatus::failed;
    outcome.summary["status"] = to_string(outcome.status);
  };
  try {
    std::vector<const Observer*> columns{&energy};
    if (closest) columns.push_back(&*closest);
    write_trajectories_csv(directory / trajectories_file_name, facts, columns);
  } catch (const OutputError& error) {
    fail(error);
  }
  try {
    write_file_atomically(directory / summary_file_name, outcome.summary.dump(2) + "\n");
  } catch (const OutputError& error) {
    fail(error);
  }
  return outcome;
}

}  // namespace nonsep::host
