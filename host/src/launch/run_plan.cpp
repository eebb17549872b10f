#include "launch/run_plan.hpp"

#include <string>

#include "nonsep/core/analysis/frequency_map_indicator.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/run_files.hpp"

namespace nonsep::host {

std::vector<ParameterSet> parameter_sets(const Job& job, const std::vector<std::size_t>& set_of) {
  std::vector<ParameterSet> sets;
  for (std::size_t b = 0; b < set_of.size(); ++b)
    if (b == 0 || set_of[b] != set_of[b - 1]) sets.push_back({b, job.parameter_set(set_of[b])});
  return sets;
}

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
          run_block_size_for(options.whole_ensemble > 0 ? options.whole_ensemble : job.initial.count),
          parameter_sets(job, job.initial.parameter_set),
          run.analysis.tangent_indicators(),
          options.chunk_seconds};
}

// /analysis/error_estimate's second run: every trajectory with half the step (2N steps), recorded at the steps that
// the run compares (error_estimate.hpp). Throws std::runtime_error when it fails as a whole.
FineRun run_finer(const LoadedJob& loaded, const RunOptions& options) {
  const SingleRun& run = loaded.job.run();
  const TimeGrid& time = run.time;
  EnsembleSetup setup = driver_setup(loaded, options);
  setup.time = time.subdivided(2);
  setup.tangent_vectors = 0;
  FineRun fine(loaded.job.initial.count, loaded.job.initial.dimension, error_estimate_steps(time.steps, run.every));
  EnsembleDriver driver(loaded.plugin, loaded.model, setup);
  driver.add_observer(fine);
  if (driver.run() == DriverEnd::failed)
    throw std::runtime_error("the error estimate's run with half the step failed: " + driver.error());
  return fine;
}

std::optional<Checkpoint> resumed_state(const LoadedJob& loaded, const RunOptions& options,
                                        const CheckpointIdentity& identity) {
  if (!options.resume) return std::nullopt;
  return load_checkpoint(options.output_directory / checkpoint_file_name, loaded, identity);
}

}  // namespace

RunPlan::RunPlan(const LoadedJob& loaded, const RunOptions& options)
    : directory(options.output_directory),
      folder_(options.folder ? options.folder
                             : std::make_shared<const RunFolder>(directory, options.work_unit ? "unit" : "run",
                                                                 loaded.job.file, folder_use(options))),
      identity_(checkpoint_identity(loaded, options.scheme_choice)),
      resumed_(resumed_state(loaded, options, identity_)),
      driver(loaded.plugin, loaded.model, driver_setup(loaded, options)),
      energy(loaded.job.initial.count, driver.energy_available() ? loaded.job.run().energy_every : 0,
             loaded.job.run().analysis.max_relative_energy_error),
      runaway(loaded.job.initial.q, loaded.job.initial.p, loaded.job.initial.count, loaded.job.initial.dimension,
              driver.time()) {
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
  for (const auto& indicator : run.analysis.sampled_indicators())
    sampled.emplace_back(std::make_unique<SampledIndicatorObserver>(directory, indicator, driver.time(),
                                                                    job.initial.dimension, count, options.resume));
  // An earlier run's files of a frequency map this run does not make, or does not make whole.
  const SampledIndicatorObserver* frequencies = sampled_indicator("frequencies");
  if (!frequencies) remove_stale(directory / FrequencyMapIndicator::signals_file_name);
  if (!frequencies || frequencies->indicator().needs().samples.spectra_file.empty())
    remove_stale(directory / FrequencyMapIndicator::spectra_file_name);
  const std::uint64_t series_every = run.analysis.lyapunov ? run.analysis.lyapunov->every : 0;
  if (run.analysis.tangent_vectors() > 0)
    chaos.emplace(directory / IndicatorColumns::file_name, run.analysis.tangent_indicators(), series_every,
                  driver.records(), options.resume);
  if (!chaos || series_every == 0) remove_stale(directory / IndicatorColumns::file_name);
  if (run.analysis.error_estimate)
    estimate.emplace(directory / ErrorEstimateObserver::file_name, run_finer(loaded, options),
                     Integrator::describe(run.integrator).order.value(), job.initial.dimension, options.resume);
  else
    remove_stale(directory / ErrorEstimateObserver::file_name);
  watch(energy);
  watch(runaway);
  if (chaos) watch(*chaos);
  if (closest) watch(*closest);
  if (samples) watch(*samples);
#ifdef NONSEP_HAVE_HDF5
  if (hdf5_samples) watch(*hdf5_samples);
#endif
  if (poincare) watch(*poincare);
  for (const auto& observer : sampled) watch(*observer);
  if (estimate) watch(*estimate);
  saver.emplace(directory / checkpoint_file_name, identity_, run.checkpoint, driver, checkpointed);
  progress.emplace(options.progress, options.progress_interval, driver, &energy, options.progress_label,
                   options.progress_schedule);
  for (Observer* observer : observers) driver.add_observer(*observer);
  driver.add_observer(*saver);
  driver.add_observer(*progress);
  if (resumed_) resume(*std::move(resumed_));
  resumed_.reset();
}

// The checkpoint's state to the driver, and to each observer its own (by its name()).
void RunPlan::resume(Checkpoint checkpoint) {
  driver.restore(std::move(checkpoint.driver));
  for (CheckpointedObserver* observer : checkpointed)
    if (!observer->name().empty()) {
      const std::string name = observer->name();
      if (!checkpoint.observers.contains(name))
        throw CheckpointError((directory / checkpoint_file_name).string() + " is damaged (no state for " + name + ")");
      observer->restore(checkpoint.observers[name]);
    }
}

}  // namespace nonsep::host
