#include "launch/run_plan.hpp"

#include <string>

#include "nonsep/host/output/atomic_files.hpp"
#include "output/run_summary.hpp"

namespace nonsep::host {

namespace {

// An earlier run's file that this run does not write would mislead.
void remove_stale(const std::filesystem::path& path) { remove_file(path); }

EnsembleSetup driver_setup(const LoadedJob& loaded, const RunOptions& options) {
  const Job& job = loaded.job;
  const SingleRun& run = job.run();
  return {run.integrator,
          run.time,
          job.initial.dimension,
          job.initial.q,
          job.initial.p,
          options.threads,
          options.stop_requested,
          run.analysis.tangent_vectors(),
          run.analysis.lyapunov ? run.analysis.lyapunov->renormalize_every : 1,
          run_block_size_for(options.whole_ensemble > 0 ? options.whole_ensemble : job.initial.count)};
}

std::optional<Checkpoint> resumed_state(const LoadedJob& loaded, const RunOptions& options) {
  if (!options.resume) return std::nullopt;
  return load_checkpoint(options.output_directory / checkpoint_file_name, loaded);
}

}  // namespace

RunPlan::RunPlan(const LoadedJob& loaded, const RunOptions& options)
    : directory(options.output_directory),
      folder_(directory, options.work_unit ? "unit" : "run", loaded.job.file, folder_use(options)),
      resumed_(resumed_state(loaded, options)),
      driver(loaded.plugin, loaded.model, driver_setup(loaded, options)),
      energy(loaded.job.initial.count, driver.energy_available() ? loaded.job.run().energy_every : 0,
             loaded.job.run().analysis.max_relative_energy_error),
      runaway(loaded.job.initial.q, loaded.job.initial.p, loaded.job.initial.count, loaded.job.initial.dimension,
              driver.time().t_end) {
  const Job& job = loaded.job;
  const SingleRun& run = job.run();
  const std::size_t count = job.initial.count;
  if (run.analysis.closest_return_after)
    closest.emplace(*run.analysis.closest_return_after, job.initial.dimension, job.initial.q, job.initial.p);
  const bool hdf5 = run.format == OutputFormat::hdf5;
  if (run.every > 0 && !hdf5) {
    samples.emplace(directory / SampleWriter::file_name, job.initial.dimension, count, run.every, driver.time(),
                    options.resume);
  } else {
    remove_stale(directory / SampleWriter::file_name);
  }
#ifdef NONSEP_HAVE_HDF5
  if (run.every > 0 && hdf5)
    hdf5_samples.emplace(directory / results_file_name, job.initial.dimension, count, run.every, driver.time(),
                         options.resume);
#else
  if (hdf5) throw OutputError("output.format \"hdf5\": this build of nonsep has no HDF5");  // the reader refuses it
#endif
  if (!hdf5 || (run.every == 0 && !options.resume)) remove_stale(directory / results_file_name);
  if (run.analysis.poincare)
    poincare.emplace(directory / PoincareSectionObserver::file_name, *run.analysis.poincare, run.integrator,
                     driver.time(), job.initial.dimension, count, driver.energy_available(), options.resume);
  else
    remove_stale(directory / PoincareSectionObserver::file_name);
  if (run.analysis.tangent_vectors() > 0)
    chaos.emplace(directory / LyapunovMegnoObserver::file_name,
                  run.analysis.lyapunov ? run.analysis.lyapunov->vectors : 0, run.analysis.megno,
                  run.analysis.lyapunov ? run.analysis.lyapunov->every : 0, driver.records(), options.resume);
  if (!chaos || !run.analysis.lyapunov || run.analysis.lyapunov->every == 0)
    remove_stale(directory / LyapunovMegnoObserver::file_name);
  observers.push_back(&energy);
  observers.push_back(&runaway);
  if (chaos) observers.push_back(&*chaos);
  if (closest) observers.push_back(&*closest);
  if (samples) observers.push_back(&*samples);
#ifdef NONSEP_HAVE_HDF5
  if (hdf5_samples) observers.push_back(&*hdf5_samples);
#endif
  if (poincare) observers.push_back(&*poincare);
  saver.emplace(directory / checkpoint_file_name, job_fingerprint(loaded), run.checkpoint, driver, observers);
  progress.emplace(options.progress, options.progress_interval, driver, &energy);
  for (Observer* observer : observers) driver.add_observer(*observer);
  driver.add_observer(*saver);
  driver.add_observer(*progress);
  if (resumed_) resume(*std::move(resumed_));
  resumed_.reset();
}

// The checkpoint's state to the driver, and to each observer its own (by its name()).
void RunPlan::resume(Checkpoint checkpoint) {
  driver.restore(std::move(checkpoint.driver));
  for (Observer* each : observers)
    if (auto* observer = dynamic_cast<CheckpointedObserver*>(each); observer && !observer->name().empty()) {
      const std::string name = observer->name();
      if (!checkpoint.observers.contains(name))
        throw CheckpointError((directory / checkpoint_file_name).string() + " is damaged (no state for " + name + ")");
      observer->restore(checkpoint.observers[name]);
    }
}

}  // namespace nonsep::host
