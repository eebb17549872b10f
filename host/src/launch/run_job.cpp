#include "nonsep/host/launch/run_job.hpp"

#include <algorithm>
#include <chrono>
#include <optional>

#include "launch/run_plan.hpp"
#include "launch/run_summary.hpp"
#include "nonsep/core/analysis/frequency_map_indicator.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#ifdef NONSEP_HAVE_HDF5
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
           "found by TOMS 748 (core/include/nonsep/core/analysis/poincare_crossing.hpp)"}};
}

// The summary of an indicator that needs samples: what its sample store (sampled_indicator.hpp) sampled and
// analysed, its columns, settings and files; a frequency map's with its method, window and units.
nlohmann::ordered_json sampled_facts(const SampledIndicatorObserver& observer) {
  std::vector<std::string> columns;
  observer.columns(columns);
  const SampleNeeds needs = observer.indicator().needs().samples;
  const bool map = dynamic_cast<const FrequencyMapIndicator*>(&observer.indicator()) != nullptr;
  nlohmann::ordered_json facts = {{"signals", observer.signals()},
                                  {"signal", "q_k + i p_k of each degree of freedom k listed"},
                                  {"every", needs.every},
                                  {"samples", observer.samples()},
                                  {"tau", observer.tau()}};
  if (map) {
    facts["window"] = "Hann (Laskar's window of order 1)";
    facts["method"] = "NAFF (core/include/nonsep/core/analysis/frequency_analysis.hpp)";
  }
  facts["columns"] = columns;
  if (map) facts["units"] = "radians per unit time, signed";
  facts["analysed"] = observer.analysed();
  facts["signals_file"] = needs.file;
  for (const auto& [name, value] : observer.indicator().settings())
    if (!facts.contains(name)) facts[name] = value;
  facts["spectra_file"] =
      needs.spectra_file.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(needs.spectra_file);
  return facts;
}

nlohmann::ordered_json tangent_facts(const Analysis& analysis) {
  nlohmann::ordered_json facts = {
      {"vectors", analysis.tangent_vectors()},
      {"first_vector",
       "(1, 1/2, ..., 1/(2n)) over (dq, dp), normalised; vector j >= 1 starts as the unit vector of "
       "component j (run/tangent_block.hpp)"},
      {"method",
       "the exact tangent map of the run's integrator (core/include/nonsep/core/runtime/tangent_integrator.hpp)"}};
  const IndicatorList indicators = analysis.tangent_indicators();
  for (const auto& indicator : indicators) {
    if (indicator->name() == "lyapunov") {
      const LyapunovAnalysis& l = *analysis.lyapunov;
      facts["lyapunov"] = {{"exponents", l.vectors},
                           {"renormalize_every", l.renormalize_every},
                           {"columns", indicator->description()},
                           {"series", l.every > 0 ? nlohmann::ordered_json(IndicatorColumns::file_name) : nullptr},
                           {"every", l.every}};
      continue;
    }
    nlohmann::ordered_json entry = nlohmann::ordered_json::object();
    for (const auto& [name, value] : indicator->settings()) entry[name] = value;
    entry["columns"] = indicator->description();
    facts[indicator->name()] = std::move(entry);
  }
  const auto with_factors = [](const auto& indicator) { return indicator->needs().orthonormalization_factors; };
  if (std::ranges::any_of(indicators, with_factors))
    facts["alignment_indices"] =
        "the vectors of the Lyapunov exponents, with the triangular factors of their orthonormalisations "
        "(core/include/nonsep/core/analysis/alignment_indices.hpp), at the last orthonormalisation";
  return facts;
}

nlohmann::ordered_json error_estimate_facts(const ErrorEstimateObserver& estimate, double order) {
  const auto totals = estimate.totals();
  const auto number = [](const std::optional<double>& x) { return x ? nlohmann::ordered_json(*x) : nullptr; };
  nlohmann::ordered_json stopped = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < estimate.fine().trajectories(); ++i)
    if (!estimate.fine().stopped(i).empty())
      stopped.push_back({{"trajectory", i}, {"finer_run", estimate.fine().stopped(i)}});
  return {{"method",
           "a second run with half the step; Richardson extrapolation: error = |(q, p)_dt - (q, p)_dt/2| / (1 - "
           "2^-order)"},
          {"order", order},
          {"factor", richardson_factor(order)},
          {"file", ErrorEstimateObserver::file_name},
          {"separation", "|estimated error| > " + format_number(error_estimate_separation) +
                             " max(|(q, p)(t)|, |(q, p)(0)|): the estimate holds only before that time"},
          {"largest_estimated_phase_error", number(totals.largest_phase_error)},
          {"largest_estimated_relative_energy_error", number(totals.largest_energy_error)},
          {"separated", totals.separated},
          {"earliest_horizon", number(totals.earliest_horizon)},
          {"unavailable", totals.unavailable},
          {"finer_run_stopped", std::move(stopped)}};
}

// Scheme "auto": the choice, and what the run itself shows against the tolerance: the largest |dH/H0| where it
// evaluated H (measure "energy"), the largest estimated phase error of /analysis/error_estimate (measure "phase",
// when asked for); without them the pilots' prediction alone (none when the phase error grew exponentially: then
// tolerance_met is null). A note for the user when it is not met.
nlohmann::ordered_json checked_choice(nlohmann::ordered_json choice, const RunOutcome& outcome,
                                      const ErrorEstimateObserver* estimate, std::vector<std::string>& notes) {
  const double tolerance = choice["tolerance"].get<double>();
  const bool energy = choice["measure"] == "energy";
  std::optional<double> measured;
  std::string how = "the pilots' prediction";
  if (energy && outcome.largest_energy_error) {
    measured = outcome.largest_energy_error->value;
    how = "the run's largest |dH/H0| where it evaluated H";
  } else if (!energy && estimate) {
    measured = estimate->totals().largest_phase_error;
    how = "the run's error estimate (analysis.error_estimate)";
  }
  // No prediction when the pilots' phase error grew exponentially (scheme_choice.hpp): then only a measurement
  // judges the tolerance.
  const bool has_prediction = choice["estimated_error"].is_number();
  const double predicted = has_prediction ? choice["estimated_error"].get<double>() : 0.0;
  const bool judged = measured || has_prediction;
  const double error = measured && has_prediction ? std::max(*measured, predicted) : measured ? *measured : predicted;
  choice["measured_error"] = measured ? nlohmann::ordered_json(*measured) : nullptr;
  choice["measured_by"] = measured ? how : has_prediction ? "nothing (the pilots' prediction alone)" : "nothing";
  choice["tolerance_met"] = judged ? nlohmann::ordered_json(error <= tolerance) : nullptr;
  if (judged && !(error <= tolerance))
    notes.push_back("warning: scheme auto did not meet the tolerance " + format_number(tolerance) + ": " +
                    (measured ? how + " is " + format_number(*measured) : std::string()) +
                    (measured && has_prediction ? ", " : "") +
                    (has_prediction ? "the prediction " + std::string(measured ? "" : "is ") + format_number(predicted)
                                    : std::string()) +
                    (choice["amplified_round_off"].is_number()
                         ? "; the pilots measured a round-off of " +
                               format_number(choice["amplified_round_off"].get<double>()) +
                               " at the pilot horizon on these orbits (they amplify each step's rounding), which no "
                               "smaller step reduces"
                         : std::string()));
  return choice;
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
  RunPlan plan(loaded, options);
  const std::filesystem::path& directory = plan.directory;
  const EnsembleDriver& driver = plan.driver;
  const bool hdf5 = run.format == OutputFormat::hdf5;

  const DriverEnd end = plan.driver.run();
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
  outcome.largest_energy_error = plan.energy.largest();
  outcome.runaways = plan.runaway.runaways();
  if (!loaded.plugin.thread_safe() && options.threads != 1)
    outcome.notes.push_back("ran on one thread: the plugin '" + loaded.plugin.name() +
                            "' declares \"thread_safe\": false (plugin_abi.h)");
  nlohmann::ordered_json choice;
  if (!options.scheme_choice.is_null())
    choice = checked_choice(options.scheme_choice, outcome, plan.estimate ? &*plan.estimate : nullptr, outcome.notes);
  const RunFacts facts{loaded,
                       directory,
                       driver,
                       outcome,
                       run.every > 0 && !hdf5,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  outcome.summary = run_summary(facts);
  if (plan.poincare) outcome.summary["analysis"]["poincare"] = poincare_facts(*run.analysis.poincare, *plan.poincare);
  if (plan.chaos) outcome.summary["analysis"]["tangent_map"] = tangent_facts(run.analysis);
  for (const auto& sampled : plan.sampled) outcome.summary["analysis"][sampled->name()] = sampled_facts(*sampled);
  if (!choice.is_null()) outcome.summary["scheme_choice"] = std::move(choice);
  if (plan.estimate)
    outcome.summary["analysis"]["error_estimate"] =
        error_estimate_facts(*plan.estimate, Integrator::describe(run.integrator).order.value());
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
    std::vector<const TrajectoryColumns*> columns{&plan.energy};
    if (plan.closest) columns.push_back(&*plan.closest);
    if (plan.poincare) columns.push_back(&*plan.poincare);
    for (const auto& sampled : plan.sampled) columns.push_back(sampled.get());
    if (plan.chaos) columns.push_back(&*plan.chaos);
    if (plan.estimate) columns.push_back(&*plan.estimate);
    write_trajectories_csv(directory / trajectories_file_name, facts, columns);
  } catch (const OutputError& error) {
    fail(error);
  }
#ifdef NONSEP_HAVE_HDF5
  // After trajectories.csv, which it copies, and before summary.json, so that a failure here is in summary.json.
  if (hdf5) try {
      write_results_file(directory / results_file_name, run.every > 0, directory, outcome.summary);
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
