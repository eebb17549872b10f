// Scheme "auto": the choice from the pilots (pilots.hpp), its record and its description (scheme_choice.hpp).
#include "nonsep/host/study/scheme_choice.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/number_format.hpp"
#include "pilots.hpp"

namespace nonsep::host {

using nlohmann::ordered_json;

namespace {

ordered_json number_or_null(double x, bool known) {
  return known && std::isfinite(x) ? ordered_json(x) : ordered_json(nullptr);
}

// The choice by `measure`: the pilots at each fraction of t_end in turn until some candidate is usable.
SchemeChoice choose_by(const LoadedJob& loaded, const RunOptions& options, AutoScheme::Measure measure) {
  SchemeChoice choice;
  choice.tolerance = loaded.job.run().auto_scheme->tolerance;
  choice.measure = measure;
  choice.chosen_by = measure;
  std::optional<std::size_t> best;
  std::string reasons;
  for (const double fraction : auto_pilot_fractions) {
    run_pilots(loaded, options, choice, fraction);
    reasons = "; pilots to t = " + format_number(choice.pilot_horizon);
    for (std::size_t i = 0; i < choice.pilots.size(); ++i) {
      const PilotResult& pilot = choice.pilots[i];
      if (!pilot.excluded.empty()) {
        reasons += "; " + pilot.candidate.label + ": " + pilot.excluded;
        continue;
      }
      if (!best || pilot.predicted_seconds < choice.pilots[*best].predicted_seconds) best = i;
    }
    if (best) break;
  }
  if (!best)
    throw ChoiceFailed("scheme auto found no scheme for tolerance " + format_number(choice.tolerance) + reasons);
  choice.chosen = *best;
  choice.subdivision = choice.pilots[*best].steps / loaded.job.run().time.steps;
  return choice;
}

// Whether a usable candidate's pilots saw the phase error grow faster than t^max_growth_exponent over their second
// half: exponentially, as on a chaotic orbit, where no power of t extrapolates it.
bool grows_exponentially(const SchemeChoice& choice) {
  return std::any_of(choice.pilots.begin(), choice.pilots.end(), [](const PilotResult& pilot) {
    return pilot.excluded.empty() && pilot.envelope_growth && *pilot.envelope_growth > max_growth_exponent;
  });
}

}  // namespace

SchemeChoice choose_scheme(const LoadedJob& loaded, const RunOptions& options) {
  SchemeChoice choice = choose_by(loaded, options, loaded.job.run().auto_scheme->measure);
  if (choice.measure == AutoScheme::Measure::energy) return choice;
  // One degree of freedom is integrable, never chaotic: there a fast growth within a period is not judged.
  const bool judged = loaded.job.initial.dimension >= 2;
  choice.phase_growth = judged && grows_exponentially(choice) ? PhaseGrowth::exponential : PhaseGrowth::polynomial;
  // The phase error at t_end cannot be predicted: the step is chosen by the energy, which a chaotic orbit does not
  // amplify, when the model has it (else the phase pilots' choice stands, unpromised).
  if (choice.phase_growth == PhaseGrowth::polynomial || !loaded.plugin.has_energy()) return choice;
  try {
    SchemeChoice by_energy = choose_by(loaded, options, AutoScheme::Measure::energy);
    by_energy.measure = AutoScheme::Measure::phase;
    by_energy.phase_growth = choice.phase_growth;
    by_energy.phase_pilots = std::move(choice.pilots);
    by_energy.phase_pilot_horizon = choice.pilot_horizon;
    by_energy.pilot_seconds += choice.pilot_seconds;
    by_energy.pilot_state_steps += choice.pilot_state_steps;
    EvaluationCounts& total = by_energy.pilot_evaluations;
    const EvaluationCounts& phase = choice.pilot_evaluations;
    total.grad_T += phase.grad_T;
    total.grad_V += phase.grad_V;
    total.grad_H += phase.grad_H;
    total.grad_K += phase.grad_K;
    total.grad_U += phase.grad_U;
    return by_energy;
  } catch (const PilotsInterrupted&) {
    throw;
  } catch (const ChoiceFailed&) {
    return choice;  // no candidate meets the tolerance on the energy either: the phase pilots' choice stands
  }
}

std::string choice_warning(const SchemeChoice& choice) {
  if (choice.phase_growth != PhaseGrowth::exponential) return "";
  const PilotResult& chosen = choice.pilots[choice.chosen];
  return "warning: scheme auto: the pilots' phase error grows exponentially (faster than t^" +
         format_number(max_growth_exponent) + " from t = " +
         format_number(
             (choice.chosen_by == AutoScheme::Measure::energy ? choice.phase_pilot_horizon : choice.pilot_horizon) /
             2) +
         " on), as on a chaotic orbit: the phase error at t_end cannot be predicted, and the tolerance " +
         format_number(choice.tolerance) + " on it is not promised; " +
         (choice.chosen_by == AutoScheme::Measure::energy
              ? "the step was chosen by the energy instead (largest |dH/H0| predicted " +
                    format_number(chosen.predicted_error) + ")"
              : "the step is the phase pilots' choice (the model has no energy to choose by)") +
         ". Measure the phase error with \"analysis\": {\"error_estimate\": true} (it says when the runs separate), "
         "or ask for \"measure\": \"energy\"";
}

void apply_choice(Job& job, const SchemeChoice& choice) {
  SingleRun& run = std::get<SingleRun>(job.plan);
  const std::uint64_t m = choice.subdivision;
  run.integrator = choice.pilots[choice.chosen].candidate.spec;
  run.time = run.time.subdivided(m);
  run.every *= m;  // energy_every keeps counting the run's own steps: 1 is still every step
  run.checkpoint.every_steps *= m;
  if (run.analysis.lyapunov) {
    run.analysis.lyapunov->every *= m;
    run.analysis.lyapunov->renormalize_every *= m;
  }
  for (auto& indicator : run.analysis.indicators)  // the same sampling times
    if (needs_samples(*indicator)) {
      auto resampled = indicator->sampling_every(indicator->needs().samples.every * m);
      if (!resampled) throw std::logic_error(indicator->name() + " cannot sample at scheme auto's step");
      indicator = std::move(resampled);
    }
}

void apply_recorded_choice(LoadedJob& loaded, const nlohmann::ordered_json& recorded,
                           const std::filesystem::path& checkpoint) {
  const auto refuse = [&](const std::string& why) {
    throw CheckpointError(checkpoint.string() + " belongs to a different job: its choice of scheme auto " + why +
                          "; run with --force to start over, or resume with the job that wrote it");
  };
  const nlohmann::ordered_json& chosen = recorded.contains("chosen") ? recorded["chosen"] : nlohmann::ordered_json();
  const nlohmann::ordered_json& m =
      recorded.contains("subdivision") ? recorded["subdivision"] : nlohmann::ordered_json();
  if (!chosen.is_string() || !m.is_number_unsigned() || m.get<std::uint64_t>() == 0)
    refuse("has no scheme and subdivision");
  SchemeChoice choice;
  for (AutoCandidate& candidate : auto_candidates(loaded))
    if (candidate.label == chosen.get<std::string>()) {
      choice.pilots.emplace_back();
      choice.pilots.back().candidate = std::move(candidate);
    }
  if (choice.pilots.empty()) refuse("is " + chosen.get<std::string>() + ", which this job does not offer");
  choice.subdivision = m.get<std::uint64_t>();
  if (loaded.job.run().time.steps > max_steps / choice.subdivision)
    refuse("subdivides the steps by " + std::to_string(choice.subdivision) + ", past " + std::to_string(max_steps) +
           " steps");
  apply_choice(loaded.job, choice);
}

namespace {

ordered_json candidates_json(const std::vector<PilotResult>& pilots) {
  ordered_json candidates = ordered_json::array();
  for (const PilotResult& pilot : pilots) {
    const bool usable = pilot.excluded.empty();
    const double order = Integrator::describe(pilot.candidate.spec).order.value();
    candidates.push_back({{"label", pilot.candidate.label},
                          {"scheme", pilot.candidate.spec.scheme},
                          {"order", Integrator::describe(pilot.candidate.spec).order.to_string()},
                          {"excluded", usable ? ordered_json(nullptr) : ordered_json(pilot.excluded)},
                          {"pilot_steps", pilot.pilot_steps ? ordered_json(pilot.anchor_steps) : ordered_json(nullptr)},
                          {"pilot_dt", number_or_null(pilot.pilot_dt, pilot.pilot_steps > 0)},
                          {"pilot_error", number_or_null(pilot.pilot_error, pilot.pilot_steps > 0)},
                          {"error_ratio_per_halving", number_or_null(pilot.ratio, pilot.pilot_steps > 0)},
                          {"round_off", number_or_null(pilot.round_off, pilot.pilot_steps > 0)},
                          {"expected_ratio", std::pow(2.0, order)},
                          {"growth_exponent", number_or_null(pilot.growth, pilot.pilot_steps > 0)},
                          {"envelope_growth_exponent",
                           number_or_null(pilot.envelope_growth.value_or(0.0), pilot.envelope_growth.has_value())},
                          {"seconds_per_step", number_or_null(pilot.seconds_per_step, pilot.pilot_steps > 0)},
                          {"steps", usable ? ordered_json(pilot.steps) : ordered_json(nullptr)},
                          {"predicted_error", number_or_null(pilot.predicted_error, usable)},
                          {"predicted_seconds", number_or_null(pilot.predicted_seconds, usable)}});
  }
  return candidates;
}

const char* measure_name(AutoScheme::Measure measure) {
  return measure == AutoScheme::Measure::phase ? "phase" : "energy";
}

}  // namespace

ordered_json to_json(const SchemeChoice& choice) {
  const PilotResult& chosen = choice.pilots[choice.chosen];
  const EvaluationCounts& e = choice.pilot_evaluations;
  const bool asked = choice.chosen_by == choice.measure;  // false: chosen by the energy for a phase tolerance
  // The phase error at t_end of an exponentially growing one is not predicted (its pilots' extrapolation stays in
  // "candidates" or "phase_candidates").
  const bool predicted = choice.phase_growth != PhaseGrowth::exponential;
  return {{"tolerance", choice.tolerance},
          {"measure", measure_name(choice.measure)},
          {"phase_error_growth", choice.phase_growth == PhaseGrowth::not_measured  ? ordered_json(nullptr)
                                 : choice.phase_growth == PhaseGrowth::exponential ? ordered_json("exponential")
                                                                                   : ordered_json("polynomial")},
          {"chosen_by", measure_name(choice.chosen_by)},
          {"method",
           "pilots at n, 2n, 4n steps to the pilot horizon; error at t_end predicted as e_p (h / h_p)^order "
           "(t_end / t_p)^growth_exponent, aimed at tolerance / " +
               format_number(auto_safety)},
          {"pilot_horizon", choice.pilot_horizon},
          {"pilot_states", choice.pilot_states},
          {"amplified_round_off", number_or_null(choice.amplified_round_off, choice.amplified_round_off > 0.0)},
          {"candidates", candidates_json(choice.pilots)},
          {"phase_candidates", asked ? ordered_json(nullptr) : candidates_json(choice.phase_pilots)},
          {"phase_pilot_horizon", asked ? ordered_json(nullptr) : ordered_json(choice.phase_pilot_horizon)},
          {"chosen", chosen.candidate.label},
          {"subdivision", choice.subdivision},
          {"estimated_error", predicted ? ordered_json(chosen.predicted_error) : ordered_json(nullptr)},
          {"estimated_error_meets_tolerance",
           predicted ? ordered_json(chosen.predicted_error <= choice.tolerance) : ordered_json(nullptr)},
          {"estimated_energy_error", asked ? ordered_json(nullptr) : ordered_json(chosen.predicted_error)},
          {"pilot_cost",
           {{"wall_seconds", choice.pilot_seconds},
            {"state_steps", choice.pilot_state_steps},
            {"evaluations",
             {{"grad_T", e.grad_T},
              {"grad_V", e.grad_V},
              {"grad_H", e.grad_H},
              {"grad_K", e.grad_K},
              {"grad_U", e.grad_U}}}}}};
}

std::string describe_auto(const LoadedJob& loaded) {
  return describe_auto(loaded.job, auto_model(loaded.plugin), true);
}

std::string describe_auto(const Job& job, const AutoModel& model, bool loaded) {
  const AutoScheme& asked = *job.run().auto_scheme;
  std::string names;
  for (const AutoCandidate& candidate : auto_candidates(job, model))
    names += (names.empty() ? "" : ", ") + candidate.label;
  const std::size_t states = pilot_indices(job.initial).size();
  // Before the states are placed on an energy shell, some may be left out: the pilots are at most these.
  const bool at_most = !loaded && job.initial.shell;
  return "scheme auto: tolerance " + format_number(asked.tolerance) + " on the " +
         (asked.measure == AutoScheme::Measure::phase ? "phase-space error at t_end" : "largest |dH/H0|") +
         "; would try " + names + " with pilot runs of " + (at_most ? "at most " : "") + std::to_string(states) +
         " state(s) to t = " + format_number(job.run().time.t_end) + " (at most " +
         std::to_string(auto_pilot_max_steps) +
         " steps each; to t_end / 8, then t_end / 64, when none is usable), then run the cheapest that meets it";
}

}  // namespace nonsep::host
