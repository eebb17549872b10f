#include "nonsep/host/cluster/distributed_run.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

#include "cluster/unit_seal.hpp"
#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/cluster/merge_outputs.hpp"
#include "nonsep/host/cluster/merge_results_h5.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/run_folder.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#ifdef NONSEP_HAVE_HDF5
#include "output/results_h5.hpp"
#endif

namespace nonsep::host {

namespace {

using nlohmann::ordered_json;
constexpr const char* plan_name = "plan.json";
constexpr int plan_format = 2;            // 2: "stepping"
constexpr std::size_t target_units = 64;  // enough to balance a few dozen ranks; each unit costs a folder and a merge

std::filesystem::path unit_folder(const std::filesystem::path& directory, std::size_t unit) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", unit);
  return directory / units_folder / name;
}

struct Plan {
  std::size_t trajectories = 0, unit_size = 0, units = 0;

  // The cut of an ensemble of `count` trajectories: the same on every rank and for any number of ranks.
  static Plan of(std::size_t count) {
    const std::size_t size = host::unit_size(count);
    return {count, size, (count + size - 1) / size};
  }
  std::size_t first(std::size_t unit) const { return unit * unit_size; }
  std::size_t size(std::size_t unit) const { return std::min(unit_size, trajectories - first(unit)); }
};

// With how the ranks step (stepping_identity, checkpoint_file.hpp): a unit started on a resume computes its numbers
// as the finished ones did.
ordered_json plan_json(const Plan& plan, const std::string& fingerprint, const std::string& stepping) {
  return {{"format", plan_format}, {"trajectories", plan.trajectories}, {"unit_size", plan.unit_size},
          {"units", plan.units},   {"job_fingerprint", fingerprint},    {"stepping", stepping}};
}

// The job restricted to `size` trajectories from `first`.
LoadedJob unit_job(const LoadedJob& loaded, std::size_t first, std::size_t size) {
  LoadedJob unit = loaded;
  InitialStates& initial = unit.job.initial;
  const std::size_t n = initial.dimension;
  initial.q.assign(loaded.job.initial.q.begin() + static_cast<std::ptrdiff_t>(first * n),
                   loaded.job.initial.q.begin() + static_cast<std::ptrdiff_t>((first + size) * n));
  initial.p.assign(loaded.job.initial.p.begin() + static_cast<std::ptrdiff_t>(first * n),
                   loaded.job.initial.p.begin() + static_cast<std::ptrdiff_t>((first + size) * n));
  initial.count = size;
  if (const auto& sets = loaded.job.initial.parameter_set; !sets.empty())
    initial.parameter_set.assign(sets.begin() + static_cast<std::ptrdiff_t>(first),
                                 sets.begin() + static_cast<std::ptrdiff_t>(first + size));
  return unit;
}

// What unit `u`'s folder must hold (unit_seal.hpp).
UnitIdentity unit_identity(const LoadedJob& loaded, const Plan& plan, std::size_t u) {
  return {u, plan.first(u), plan.size(u), job_fingerprint(unit_job(loaded, plan.first(u), plan.size(u)))};
}

// Rank 0: takes the output folder and writes `plan` to units/plan.json (fresh) or checks it against it (resume): the
// plan, that units/ and every unit folder in it are folders (no links out of the output folder), and every sealed
// unit (unit_seal.hpp). Throws what RunFolder and the checkpoint checks throw.
void prepare_folder(const LoadedJob& loaded, const RunOptions& options, const Plan& plan,
                    std::optional<RunFolder>& folder) {
  const std::filesystem::path& directory = options.output_directory;
  folder.emplace(directory, "run", loaded.job.file, folder_use(options));
  const std::string fingerprint = job_fingerprint(loaded), stepping = stepping_identity(loaded);
  const auto path = directory / units_folder / plan_name;
  if (options.resume) {
    check_real_folder(directory / units_folder, false);
    ordered_json saved;
    try {
      saved = ordered_json::parse(read_regular_file(path, 1 << 16).value_or(""));
    } catch (const std::exception&) {
      throw CheckpointError(path.string() + " is missing or damaged: there is no distributed run to resume here");
    }
    if (saved.contains("stepping") && saved["stepping"].is_string())
      check_stepping(saved["stepping"].get<std::string>(), loaded, path);
    if (saved != plan_json(plan, fingerprint, stepping))
      throw CheckpointError(
          path.string() + " was written by another job, or by this job before it was changed" +
          (saved.contains("job_fingerprint") && saved["job_fingerprint"].is_string()
               ? " (its " + what_differs(saved["job_fingerprint"].get<std::string>(), fingerprint) + ")"
               : std::string()) +
          "; run it again without --resume (--force discards the units)");
    for (std::size_t u = 0; u < plan.units; ++u) {
      const auto unit = unit_folder(directory, u);
      check_real_folder(unit, true);
      if (has_seal(unit)) verify_unit(unit, unit_identity(loaded, plan, u));
    }
    return;
  }
  std::error_code error;
  std::filesystem::create_directories(directory / units_folder, error);
  if (error) throw OutputError("cannot create " + (directory / units_folder).string() + ": " + error.message());
  write_file_atomically(path, plan_json(plan, fingerprint, stepping).dump(2) + "\n");
}

enum class UnitState { fresh, checkpointed, done };

// Done only when sealed (unit_seal.hpp): a unit that wrote its summary but was killed before its seal runs again.
UnitState unit_state(const std::filesystem::path& folder) {
  if (has_seal(folder)) return UnitState::done;
  std::error_code error;
  if (std::filesystem::exists(std::filesystem::symlink_status(folder / checkpoint_file_name, error)))
    return UnitState::checkpointed;
  return UnitState::fresh;
}

std::string failure_text(const std::exception& error) {
  if (dynamic_cast<const CheckpointError*>(&error)) return std::string("cannot resume: ") + error.what();
  return error.what();
}

// Rank 0, every unit done: the run's files from the units', each unit verified first (unit_seal.hpp).
RunOutcome merge_units(const LoadedJob& loaded, const RunOptions& options, const Plan& plan, double wall_seconds) {
  const std::filesystem::path& directory = options.output_directory;
  check_real_folder(directory / units_folder, false);
  std::vector<UnitFile> parts;
  std::vector<ordered_json> summaries;
  std::vector<std::size_t> firsts;
  for (std::size_t u = 0; u < plan.units; ++u) {
    parts.push_back({unit_folder(directory, u), plan.first(u)});
    firsts.push_back(plan.first(u));
    check_real_folder(parts.back().path, false);
    verify_unit(parts.back().path, unit_identity(loaded, plan, u));
    try {
      summaries.push_back(ordered_json::parse(read_regular_file(parts.back().path / "summary.json").value_or("")));
    } catch (const ordered_json::exception& error) {
      throw OutputError((parts.back().path / "summary.json").string() + " cannot be read: " + error.what());
    }
  }
  const auto merge = [&](const char* name, std::vector<std::string> keys) {
    if (!std::filesystem::exists(parts.front().path / name)) return;
    std::vector<UnitFile> files = parts;
    for (UnitFile& file : files) file.path /= name;
    merge_csv(files, directory / name, keys);
  };
  merge("trajectory.csv", {"step", "trajectory"});
  merge("poincare.csv", {"step", "trajectory"});
  merge("lyapunov.csv", {"step", "trajectory"});
  merge("trajectories.csv", {"trajectory"});
  for (const auto& indicator : loaded.job.run().analysis.sampled_indicators()) {
    const SampleNeeds needs = indicator->needs().samples;
    if (!needs.spectra_file.empty()) merge(needs.spectra_file.c_str(), {"trajectory"});
    if (!std::filesystem::exists(parts.front().path / needs.file)) continue;
    std::vector<UnitFile> files = parts;
    for (UnitFile& file : files) file.path /= needs.file;
    merge_signals(files, directory / needs.file);
  }
  RunOutcome outcome;
  outcome.distributed = true;
  outcome.summary = merge_summaries(summaries, firsts, plan.trajectories, directory, wall_seconds);
  write_file_atomically(directory / "summary.json", outcome.summary.dump(2) + "\n");
  const ordered_json& summary = outcome.summary;
  outcome.status =
      trajectory_status_from_string(summary["status"].get<std::string>()).value_or(TrajectoryStatus::failed);
  outcome.exit_status = exit_status_of(outcome.status);
  outcome.error = summary.value("error", "");
  outcome.steps_completed = summary["time"]["steps_completed"].get<std::uint64_t>();
  for (TrajectoryStatus status : {TrajectoryStatus::completed, TrajectoryStatus::diverged, TrajectoryStatus::failed,
                                  TrajectoryStatus::inaccurate, TrajectoryStatus::interrupted})
    outcome.counts[status] = summary["counts"][to_string(status)].get<std::size_t>();
  if (const ordered_json& largest = summary["energy"]["largest_relative_error"]; largest.is_object())
    outcome.largest_energy_error =
        LargestEnergyError{largest["value"].get<double>(), largest["trajectory"].get<std::size_t>()};
  return outcome;
}

// Rank 0, after an interrupt: summary.json says what is done; units/ is the checkpoint.
RunOutcome interrupted_outcome(const LoadedJob& loaded, const RunOptions& options, const Plan& plan,
                               const Ranks& ranks) {
  std::size_t done = 0, checkpointed = 0;
  for (std::size_t u = 0; u < plan.units; ++u) {
    const UnitState state = unit_state(unit_folder(options.output_directory, u));
    done += state == UnitState::done;
    checkpointed += state == UnitState::checkpointed;
  }
  RunOutcome outcome;
  outcome.distributed = true;
  outcome.status = TrajectoryStatus::interrupted;
  outcome.exit_status = ExitStatus::interrupted;
  outcome.counts.interrupted = plan.trajectories;
  outcome.notes.push_back(std::to_string(done) + " of " + std::to_string(plan.units) + " work units done, " +
                          std::to_string(checkpointed) + " checkpointed, in " +
                          (options.output_directory / units_folder).string());
  outcome.summary = {{"status", "interrupted"},
                     {"job", loaded.job.file.string()},
                     {"trajectories", plan.trajectories},
                     {"distributed",
                      {{"ranks", ranks.size()},
                       {"units", plan.units},
                       {"unit_size", plan.unit_size},
                       {"units_done", done},
                       {"units_checkpointed", checkpointed},
                       {"folder", units_folder},
                       {"resume", "nonsep run JOB --resume, with any number of ranks"}}}};
  write_file_atomically(options.output_directory / "summary.json", outcome.summary.dump(2) + "\n");
  return outcome;
}

// output.format "hdf5": the ranks copy the units' /samples into results.h5 together, then rank 0 adds the tables
// and attributes from the merged CSV files and summary (merge_results_h5.hpp). Collective.
void finish_results_h5(const LoadedJob& loaded, const RunOptions& options, const Plan& plan,
                       const ordered_json& summary, const Ranks& ranks) {
  const SingleRun& run = loaded.job.run();
  if (run.format != OutputFormat::hdf5) return;
#ifdef NONSEP_HAVE_HDF5
  const auto path = options.output_directory / results_file_name;
  if (run.every > 0) {
    std::vector<UnitRange> units;
    for (std::size_t u = 0; u < plan.units; ++u)
      units.push_back({unit_folder(options.output_directory, u), plan.first(u), plan.size(u)});
    merge_samples_h5(path, loaded, units, ranks);
  }
  if (ranks.rank() == 0) write_results_file(path, run.every > 0, options.output_directory, summary);
#else
  (void)options, (void)plan, (void)summary, (void)ranks;
#endif
}

}  // namespace

std::size_t unit_size(std::size_t trajectories) {
  const std::size_t per_unit = (trajectories + target_units - 1) / target_units;
  const std::size_t blocks = std::max<std::size_t>(1, (per_unit + run_block_size - 1) / run_block_size);
  return blocks * run_block_size;
}

bool has_units(const std::filesystem::path& directory) {
  std::error_code error;
  return std::filesystem::exists(directory / units_folder / plan_name, error);
}

RunOutcome run_distributed(const LoadedJob& loaded, const RunOptions& options, const Ranks& ranks) {
  const auto start = std::chrono::steady_clock::now();
  const auto fail_if_any = [&](const std::string& local) {
    const Ranks::Failure failure = ranks.first_failure(!local.empty(), local);
    if (failure.rank >= 0)
      throw RankFailure(ranks.size() > 1 ? "rank " + std::to_string(failure.rank) + ": " + failure.message
                                         : failure.message);
  };

  std::optional<RunFolder> folder;  // rank 0 holds the output folder's lock for the whole run
  std::string local_failure;
  const Plan plan = Plan::of(loaded.job.initial.count);  // rank 0 checks it against the folder's plan.json
  if (ranks.rank() == 0) {
    try {
      prepare_folder(loaded, options, plan, folder);
    } catch (const std::exception& error) {
      local_failure = failure_text(error);
    }
  }
  fail_if_any(local_failure);

  bool interrupted = false;
  // Each rank writes its own progress lines, labelled with the rank and the unit, at the run's interval across its
  // units (progress_bar.hpp): no rank waits for another to report. Lines, not a bar: the ranks share one stderr.
  const bool progress = options.progress != ProgressStyle::none && options.progress_interval > 0;
  const auto schedule = std::make_shared<ProgressSchedule>(ProgressSchedule{
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(options.progress_interval))});
  {
    Ranks::UnitCounter counter(ranks);
    while (local_failure.empty()) {
      if (options.stop_requested && options.stop_requested->load()) {
        interrupted = true;
        break;
      }
      const std::uint64_t unit = counter.next();
      if (unit >= plan.units) break;
      const auto path = unit_folder(options.output_directory, unit);
      try {
        check_real_folder(options.output_directory / units_folder, false);
        check_real_folder(path, true);
        const UnitState state = unit_state(path);
        if (state == UnitState::done) continue;  // verified by rank 0 at the start and before the merge
        RunOptions unit_options = options;
        unit_options.output_directory = path;
        unit_options.progress = progress ? ProgressStyle::lines : ProgressStyle::none;
        unit_options.progress_label = "rank " + std::to_string(ranks.rank()) + " of " + std::to_string(ranks.size()) +
                                      ", unit " + path.filename().string() + " of " + std::to_string(plan.units);
        unit_options.progress_schedule = schedule;
        unit_options.work_unit = true;
        unit_options.resume = state == UnitState::checkpointed;
        unit_options.force = !unit_options.resume;  // a unit killed before its first checkpoint starts over
        unit_options.whole_ensemble = loaded.job.initial.count;
        const LoadedJob job = unit_job(loaded, plan.first(unit), plan.size(unit));
        RunOutcome outcome;
        try {
          outcome = run_job(job, unit_options);
        } catch (const CheckpointError& error) {
          if (!unit_options.resume) throw;
          // A rank killed hard can leave a unit's files unreadable past its checkpoint (results.h5's deflated chunk
          // rewritten in place when the kill came). The plan's fingerprint already matched this job, and a unit's
          // trajectories depend only on themselves: run it again from its start, which gives the same bytes.
          std::fprintf(stderr, "nonsep: warning: work unit %s: %s; running it again from its start\n",
                       path.string().c_str(), failure_text(error).c_str());
          unit_options.resume = false;
          unit_options.force = true;
          outcome = run_job(job, unit_options);
        }
        if (outcome.exit_status == ExitStatus::interrupted)
          interrupted = true;
        else
          seal_unit(path, {unit, plan.first(unit), plan.size(unit), job_fingerprint(job)});
      } catch (const std::exception& error) {
        local_failure = "work unit " + path.string() + " (trajectories " + std::to_string(plan.first(unit)) + " to " +
                        std::to_string(plan.first(unit) + plan.size(unit) - 1) + "): " + failure_text(error);
      }
      if (interrupted) break;
    }
    ranks.barrier();  // every rank is done with the counter before it is freed
  }
  fail_if_any(local_failure);
  interrupted = ranks.any(interrupted);

  RunOutcome outcome;
  if (ranks.rank() == 0) {
    try {
      outcome = interrupted
                    ? interrupted_outcome(loaded, options, plan, ranks)
                    : merge_units(loaded, options, plan,
                                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    } catch (const std::exception& error) {
      local_failure = std::string(error.what()) + " (the units' results stay in " +
                      (options.output_directory / units_folder).string() + ")";
    }
  }
  fail_if_any(local_failure);
  if (!interrupted) {
    try {
      finish_results_h5(loaded, options, plan, outcome.summary, ranks);
    } catch (const std::exception& error) {
      local_failure = std::string(error.what()) + " (the units' results stay in " +
                      (options.output_directory / units_folder).string() + ")";
    }
    fail_if_any(local_failure);
    if (ranks.rank() == 0) {
      std::error_code ignored;
      std::filesystem::remove_all(options.output_directory / units_folder, ignored);
    }
  }
  outcome.exit_status = static_cast<ExitStatus>(ranks.max(static_cast<int>(outcome.exit_status)));
  outcome.distributed = true;
  return outcome;
}

}  // namespace nonsep::host
