#pragma once
// A loaded job made ready to run, built once and in the order its data flows: the output folder (taken,
// run_folder.hpp), the job's identity (checkpoint_identity, computed once), the state a resumed run continues from
// (checkpoint.json, read and checked against that identity here and nowhere else: checkpoint_file.hpp), the driver, the
// finer run of /analysis/error_estimate (run here, before the run), the observers the job asks for (their files opened;
// earlier runs' files this run does not write removed), the resumed state handed to the driver and to each observer,
// then the checkpoint saver (the one writer of checkpoint.json: checkpoint_saver.hpp) and the progress bar. run_job
// (run_job.hpp) runs the driver and writes the run's files from what the plan's observers hold. Internal to
// src/launch/.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/checkpoint/checkpoint_saver.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/observers/closest_return.hpp"
#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/error_estimate.hpp"
#include "nonsep/host/observers/indicator_columns.hpp"
#include "nonsep/host/observers/poincare_section.hpp"
#include "nonsep/host/observers/progress.hpp"
#include "nonsep/host/observers/runaway.hpp"
#include "nonsep/host/observers/sample_writer.hpp"
#include "nonsep/host/observers/sampled_indicator.hpp"
#include "nonsep/host/output/run_folder.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/observer.hpp"
#ifdef NONSEP_HAVE_HDF5
#include "nonsep/host/observers/hdf5_sample_writer.hpp"
#endif

namespace nonsep::host {

class RunPlan {
 public:
  // Throws, before anything is computed: FolderInUse, OutputError and CheckpointError (run_job.hpp says when).
  RunPlan(const LoadedJob& loaded, const RunOptions& options);
  RunPlan(const RunPlan&) = delete;
  RunPlan& operator=(const RunPlan&) = delete;

  const std::filesystem::path directory;

 private:
  std::shared_ptr<const RunFolder> folder_;  // RunOptions::folder, or taken here
  const CheckpointIdentity identity_;        // the saver writes it into every checkpoint
  std::optional<Checkpoint> resumed_;        // until the constructor hands it to the driver and the observers

 public:
  EnsembleDriver driver;
  EnergyErrorObserver energy;
  RunawayObserver runaway;
  std::optional<ClosestReturnObserver> closest;
  std::optional<SampleWriter> samples;
#ifdef NONSEP_HAVE_HDF5
  std::optional<Hdf5SampleWriter> hdf5_samples;
#endif
  std::optional<PoincareSectionObserver> poincare;
  std::vector<std::unique_ptr<SampledIndicatorObserver>> sampled;  // one per indicator that needs samples, in order
  std::optional<IndicatorColumns> chaos;
  std::optional<ErrorEstimateObserver> estimate;  // /analysis/error_estimate: its finer run is done by the plan
  // The observers above that the driver tells, in the order it tells them; the saver and the progress bar follow.
  std::vector<Observer*> observers;
  std::vector<CheckpointedObserver*> checkpointed;  // those of them with state for checkpoints, in the same order
  std::optional<CheckpointSaver> saver;
  std::optional<ProgressObserver> progress;

 private:
  // Adds `observer` to `observers`, and to `checkpointed` when its type has that facet.
  template <class O>
  void watch(O& observer) {
    observers.push_back(&observer);
    if constexpr (std::is_base_of_v<CheckpointedObserver, O>) checkpointed.push_back(&observer);
  }
  void resume(Checkpoint checkpoint);
  // The sample store of the indicator named `name`, or null when the job has none.
  const SampledIndicatorObserver* sampled_indicator(const std::string& name) const {
    for (const auto& observer : sampled)
      if (observer->name() == name) return observer.get();
    return nullptr;
  }
};

}  // namespace nonsep::host
