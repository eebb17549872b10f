#pragma once
// What a run writes at its end, assembled from the job and the driver: summary.json (the run's facts, written with
// nlohmann-json) and trajectories.csv (one row per trajectory; columns in launch/run_job.hpp). Both are replaced
// atomically; their names are in output/run_files.hpp. Internal to src/launch/.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/output/run_files.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

struct RunFacts {
  const LoadedJob& loaded;
  const std::filesystem::path& directory;
  const EnsembleDriver& driver;
  const RunOutcome& outcome;
  bool samples_written;
  double wall_seconds;
};

nlohmann::ordered_json run_summary(const RunFacts& facts);

// Throws OutputError.
void write_trajectories_csv(const std::filesystem::path& path, const RunFacts& facts,
                            std::span<const TrajectoryColumns* const> observers);

}  // namespace nonsep::host
