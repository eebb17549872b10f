#include "nonsep/host/launch/run_job.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/checkpoint/checkpoint_saver.hpp"
#include "nonsep/host/observers/closest_return.hpp"
#include "nonsep/host/observers/lyapunov_megno.hpp"
#include "nonsep/host/observers/poincare_section.hpp"
#include "nonsep/host/observers/progress.hpp"
#include "nonsep/host/observers/sample_writer.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "output/run_summary.hpp"
#ifdef NONSEP_HAVE_HDF5
#include "nonsep/host/observers/hdf5_sample_writer.hpp"
#include "output/results_h5.hpp"
#endif

namespace nonsep::host {

std::size_t& StatusCounts::operator[](TrajectoryStatus status) {
  switch (status) {
    case TrajectoryStatus::completed:
      return completed;
    case TrajectoryStatus::diverged:
      return diverged;
    case TrajectoryStatus::failed:
      return failed;
    case TrajectoryStatus::inaccurate:
      return inaccurate;
    default:
      return interrupted;
  }
}

namespace {

// An earlier run's file that this run does not write would mislead.
void remove_stale(const std::filesystem::path& path) { remove_file(path); }

nlohmann::ordered_json poincare_facts(const PoincareSection& section, const PoincareSectionObserver& observer) {
  const char* direction = section.direction == CrossingDirection::up     ? "+"
                          : section.direction == CrossingDirection::down ? "-"
                                                                         : "both";
  return {{"file", PoincareSectionObserver::file_name},
          {"plane", "normal . (q, p) = value"},
          {"normal", section.normal},
          {"value", section.offset},
          {"direction", direction},
          {"max_crossings", section.max_crossings ? nlohmann::ordered_json(*section.max_crossings) : nullptr},
          {"crossings", observer.total_crossings()},
          {"located_by",
           "a fractional step of the run's integrator from the state before the step, its length "
           "found by TOMS 748 (core/poincare_crossing.hpp)"}};
}

nlohmann::ordered_json tangent_facts(const Analysis& analysis) {
  nlohmann::ordered_json facts = {
      {"vectors", analysis.tangent_vectors()},
      {"first_vector",
       "(1, 1/2, ..., 1/(2n)) over (dq, dp), normalised; vector j >= 1 starts as the unit vector of "
       "component j (run/tangent_block.hpp)"},
      {"method", "the exact tangent map of the run's integrator (core/tangent_integrator.hpp)"}};
  if (const auto& l = analysis.lyapunov)
    facts["lyapunov"] = {{"exponents", l->vectors},
                         {"renormalize_every", l->renormalize_every},
                         {"columns", "trajectories.csv lyapunov0 .. lyapunov" + std::to_string(l->vectors - 1)},
                         {"series", l->every > 0 ? nlohmann::ordered_json(LyapunovMegnoObserver::file_name) : nullptr},
                         {"every", l->every}};
  if (analysis.megno)
    facts["megno"] = {{"columns", "trajectories.csv megno (Y), mean_megno (<Y>, -> 2 on quasi-periodic orbits)"}};
  return facts;
}

}  // namespace

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

FolderUse folder_use(const RunOptions& options) {
  return options.resume ? FolderUse::resume : options.force ? FolderUse::force : FolderUse::fresh;
}

RunOutcome run_job(const LoadedJob& loaded, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Job& job = loaded.job;
  const SingleRun& run = job.run();
  const std::filesystem::path& directory = options.output_directory;
  const RunFolder folder(directory, options.work_unit ? "unit" : "run", job.file, folder_use(options));
  std::optional<Checkpoint> checkpoint;
  if (options.resume) checkpoint = load_checkpoint(directory / checkpoint_file_name, loaded);

  EnsembleDriver driver(loaded.plugin, loaded.model,
                        {run.integrator, run.time, job.initial.dimension, job.initial.q, job.initial.p, options.threads,
                         options.stop_requested, run.analysis.tangent_vectors(),
                         run.analysis.lyapunov ? run.analysis.lyapunov->renormalize_every : 1,
                         run_block_size_for(options.whole_ensemble > 0 ? options.whole_ensemble : job.initial.count)});
  const std::size_t count = job.initial.count;
  EnergyErrorObserver energy(count, driver.energy_available() ? run.energy_every : 0,
                             run.analysis.max_relative_energy_error);
  std::optional<ClosestReturnObserver> closest;
  if (run.analysis.closest_return_after)
    closest.emplace(*run.analysis.closest_return_after, job.initial.dimension, job.initial.q, job.initial.p);
  const bool hdf5 = run.format == OutputFormat::hdf5;
  std::optional<SampleWriter> samples;
  if (run.every > 0 && !hdf5) {
    samples.emplace(directory / SampleWriter::file_name, job.initial.dimension, count, run.every, driver.time(),
                    options.resume);
  } else {
    remove_stale(directory / SampleWriter::file_name);
  }
#ifdef NONSEP_HAVE_HDF5
  std::optional<Hdf5SampleWriter> hdf5_samples;
  if (run.every > 0 && hdf5)
    hdf5_samples.emplace(directory / results_file_name, job.initial.dimension, count, run.every, driver.time(),
                         options.resume);
#else
  if (hdf5) throw OutputError("output.format \"hdf5\": this build of nonsep has no HDF5");  // the reader refuses it
#endif
  if (!hdf5 || (run.every == 0 && !options.resume)) remove_stale(directory / results_file_name);
  std::optional<PoincareSectionObserver> poincare;
  if (run.analysis.poincare)
    poincare.emplace(directory / PoincareSectionObserver::file_name, *run.analysis.poincare, run.integrator,
                     driver.time(), job.initial.dimension, count, driver.energy_available(), options.resume);
  else
    remove_stale(directory / PoincareSectionObserver::file_name);
  std::optional<LyapunovMegnoObserver> chaos;
  if (run.analysis.tangent_vectors() > 0)
    chaos.emplace(directory / LyapunovMegnoObserver::file_name,
                  run.analysis.lyapunov ? run.analysis.lyapunov->vectors : 0, run.analysis.megno,
                  run.analysis.lyapunov ? run.analysis.lyapunov->every : 0, driver.time(), driver.records(),
                  options.resume);
  if (!chaos || !run.analysis.lyapunov || run.analysis.lyapunov->every == 0)
    remove_stale(directory / LyapunovMegnoObserver::file_name);
  std::vector<Observer*> observers{&energy};
  if (chaos) observers.push_back(&*chaos);
  if (closest) observers.push_back(&*closest);
  if (samples) observers.push_back(&*samples);
#ifdef NONSEP_HAVE_HDF5
  if (hdf5_samples) observers.push_back(&*hdf5_samples);
#endif
  if (poincare) observers.push_back(&*poincare);
  CheckpointSaver saver(directory / checkpoint_file_name, job_fingerprint(loaded), run.checkpoint, driver, observers);
  ProgressObserver progress(options.show_progress, driver, &energy);
  for (Observer* observer : observers) driver.add_observer(*observer);
  driver.add_observer(saver);
  driver.add_observer(progress);
  if (checkpoint) {
    driver.restore(std::move(checkpoint->driver));
    for (Observer* each : observers)
      if (auto* observer = dynamic_cast<CheckpointedObserver*>(each); observer && !observer->name().empty()) {
        const std::string name = observer->name();
        if (!checkpoint->observers.contains(name))
          throw CheckpointError((directory / checkpoint_file_name).string() + " is damaged (no state for " + name +
                                ")");
        observer->restore(checkpoint->observers[name]);
      }
  }

  const DriverEnd end = driver.run();
  RunOutcome outcome;
  outcome.error = driver.error();
  outcome.trajectories = driver.records();
  // Not driver.steps_completed(), which can be the end of a chunk past the step where the last trajectory stopped
  // and so depends on how the ensemble is cut into blocks (and on MPI work units).
  for (const TrajectoryRecord& record : outcome.trajectories)
    outcome.steps_completed = std::max(outcome.steps_completed, record.final_step);
  for (const TrajectoryRecord& record : outcome.trajectories) ++outcome.counts[record.status];
  outcome.status = run_status(end, outcome.counts);
  outcome.exit_status = exit_status_of(outcome.status);
  outcome.largest_energy_error = energy.largest();
  if (!loaded.plugin.thread_safe() && options.threads != 1)
    outcome.notes.push_back("ran on one thread: the plugin '" + loaded.plugin.name() +
                            "' declares \"thread_safe\": false (plugin_abi.h)");
  const RunFacts facts{loaded,
                       directory,
                       driver,
                       outcome,
                       run.every > 0 && !hdf5,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  outcome.summary = run_summary(facts);
  if (poincare) outcome.summary["analysis"]["poincare"] = poincare_facts(*run.analysis.poincare, *poincare);
  if (chaos) outcome.summary["analysis"]["tangent_map"] = tangent_facts(run.analysis);
  if (const auto& shell = job.initial.shell)
    outcome.summary["energy_shell"] = {{"energy", shell->energy},
                                       {"solve_for", shell->solve_for},
                                       {"states", job.initial.count},
                                       {"left_out", shell->left_out}};
  const auto fail = [&](const OutputError& error) {
    outcome.error = (outcome.error.empty() ? "" : outcome.error + "; ") + error.what();
    outcome.summary["error"] = outcome.error;
    if (outcome.exit_status == ExitStatus::success) outcome.exit_status = ExitStatus::run_failed;
    if (outcome.status == TrajectoryStatus::completed) outcome.status = TrajectoryStatus::failed;
    outcome.summary["status"] = to_string(outcome.status);
  };
  try {
    std::vector<const TrajectoryColumns*> columns{&energy};
    if (closest) columns.push_back(&*closest);
    if (poincare) columns.push_back(&*poincare);
    if (chaos) columns.push_back(&*chaos);
    write_trajectories_csv(directory / trajectories_file_name, facts, columns);
  } catch (const OutputError& error) {
    fail(error);
  }
#ifdef NONSEP_HAVE_HDF5
  // After trajectories.csv, which it copies, and before summary.json, so that a failure here is in summary.json.
  if (hdf5) try {
      write_results_file(directory / results_file_name, run.every > 0, loaded, directory, outcome.summary);
    } catch (const OutputError& error) {
      fail(error);
    }
#endif
  try {
    write_file_atomically(directory / summary_file_name, outcome.summary.dump(2) + "\n");
  } catch (const OutputError& error) {
    fail(error);
  }
  return outcome;
}

}  // namespace nonsep::host
