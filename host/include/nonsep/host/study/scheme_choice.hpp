#pragma once
// Scheme "auto" (/integrator {"scheme": "auto", "tolerance": e, "measure": "phase" | "energy"}): pilot runs on the
// job's own model and states choose the scheme and the step that meet the tolerance at the least predicted cost.
//
// Candidates (auto_candidates): the catalogue's auto_orders (scheme_catalogue.hpp) that the plugin and the job
// allow, fastest first by docs/work-precision.md: the comparators' before Chin's, each by falling order. With
// Hessians and third derivatives the comparators Gauss-Legendre 16, 8, 6 and 4; Chin's schemes, which need
// gradients only: MPE 4 (not symplectic), triplet 8/3, triplet 2. Tangent vectors (/analysis/lyapunov, /megno) keep
// only the schemes that have a tangent map (nonsep::has_tangent_map). A separable part K(p) + U(q) is solved by every
// one of them.
//
// Pilots: up to auto_pilot_states of the job's states (evenly spread, the first and the last among them; with a
// sweep, as many of each parameter set's states, at least one per set, each stepped with its set's parameters as
// the run steps it, so that the choice meets the tolerance on every set), from t = 0 to the pilot horizon t_p, each
// candidate at n, 2n and 4n steps (n = 4, doubled until the three are in the
// scheme's asymptotic range: their differences fall by 2^order within a factor 2.5, or the finest is at round-off;
// at most auto_pilot_max_steps steps). The error at t_p of the 4n run is, by Richardson extrapolation,
//   phase:  |(q, p)_2n - (q, p)_4n| / (2^p - 1)          energy: max |dH/H0| over [0, t_p] of the 4n run
// (the largest over the pilot states). When that is round-off and the coarser pair's is not, the prediction starts
// from the coarser pair's measured error instead: phase |(q, p)_n - (q, p)_2n|, the n run's error (the 2n run's is
// round-off); energy the 2n run's. h_p is the step of the run whose error e_p is. Its growth from t_p / 2 to t_p
// gives an exponent a (phase: 1 to 3, energy: 0 to 3), so that the error at t_end with step h is predicted as
//   e(h) = e_p (h / h_p)^r (t_end / t_p)^a,
// r the order, or the rate the pilots showed (log2 of their error ratio) where that predicts the larger error;
// h at most t_p / n, the coarsest step the accepted ladder covers.
// The pilot horizon is t_end itself (then a = 0 plays no part) unless no candidate is usable there (a long run, at
// whose horizon even 2^14 steps are not asymptotic): then t_end / 8, then t_end / 64 (auto_pilot_fractions).
// The step is the largest h = |time.dt| / m (m a whole number, so that the output grid of time.dt is kept) with
// e(h) <= tolerance / auto_safety; the cost is the pilot's measured seconds per step times t_end / h. The candidate
// with the least cost is chosen. The pilots' cost is bounded: a candidate whose pilots have taken longer than the
// least predicted run so far is left out, so that they cost at most about that run per candidate; so is one whose
// ladder is not yet asymptotic when its error falling at twice its order from its last pilot would still need a
// longer run than that. A candidate that
// diverges, fails, or does not reach its asymptotic range is left out with the reason. When none is left the choice
// fails (ChoiceFailed).
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"

namespace nonsep::host {

// The pilots run to t_end / each of these in turn, until some candidate is usable.
inline constexpr double auto_pilot_fractions[] = {1.0, 8.0, 64.0};
inline constexpr std::size_t auto_pilot_states = 8;
inline constexpr std::uint64_t auto_pilot_max_steps = 1 << 14;  // the finest pilot of one candidate at most
inline constexpr double auto_safety = 3.0;                      // the prediction aims at tolerance / this
inline constexpr double max_growth_exponent = 3.0;              // the largest a the prediction extrapolates with

struct AutoCandidate {
  std::string label;  // "gauss 6", "triplet 8/3"
  IntegratorSpec spec;
};

// What of a model decides the candidates.
struct AutoModel {
  bool general = false;                         // given by H (PluginModel::general_hamiltonian)
  bool hessians_and_third_derivatives = false;  // the comparators need them of a product-form model
  bool hessian_products = false;                // hvp_H: the comparators' tangent maps need it
};
AutoModel auto_model(const Plugin& plugin);
// A formula model's, without compiling it: its plugin has every derivative (formula-models.md).
AutoModel auto_model(const formula::FormulaModel& model);

// The candidates of `loaded` (a single run with /integrator "auto"), in the order they are tried.
std::vector<AutoCandidate> auto_candidates(const LoadedJob& loaded);
std::vector<AutoCandidate> auto_candidates(const Job& job, const AutoModel& model);

// What the pilots measured of one candidate.
struct PilotResult {
  AutoCandidate candidate;
  std::string excluded;            // why it was left out; "" when it can be chosen
  std::uint64_t pilot_steps = 0;   // n of the accepted ladder (its runs: n, 2n, 4n steps to t_p)
  std::uint64_t anchor_steps = 0;  // the pilot run whose error e_p is: 4n, or n / 2n (phase / energy) at round-off
  double pilot_dt = 0.0;           // t_p / anchor_steps
  double pilot_error = 0.0;        // e_p: the anchor run's error at t_p
  double ratio = 0.0;              // how much the error fell from 2n to 4n (2^order in the asymptotic range)
  double round_off = 0.0;          // the 4n pilot's error is round-off at or below this (pilots.cpp)
  double growth = 0.0;             // a
  // Phase: log2 of the growth of the pilot pair's largest distance from t_p / 2 to t_p (largest over the marks up to
  // each); nothing for the energy, or when the distance is at round-off.
  std::optional<double> envelope_growth;
  double seconds_per_step = 0.0;  // of the pilot states together
  std::uint64_t steps = 0;        // of the final run, predicted
  double predicted_error = 0.0;   // e(h) at t_end
  double predicted_seconds = 0.0;
};

// How the phase error of the pilots grew over their second half (measure "phase"): by at most a power
// t^max_growth_exponent, or faster (exponentially, as on a chaotic orbit, where no prediction of the phase error at
// t_end holds).
enum class PhaseGrowth { not_measured, polynomial, exponential };

struct SchemeChoice {
  double tolerance = 0.0;
  AutoScheme::Measure measure = AutoScheme::Measure::phase;  // the one asked for
  // The measure whose pilots chose: the energy when the phase error grows exponentially and the model has it.
  AutoScheme::Measure chosen_by = AutoScheme::Measure::phase;
  PhaseGrowth phase_growth = PhaseGrowth::not_measured;
  std::vector<PilotResult> phase_pilots;  // the phase pilots, when chosen by the energy
  double phase_pilot_horizon = 0.0;       // and their horizon
  double pilot_horizon = 0.0;
  // The largest round-off the phase pilots measured above the fixed bound (pilots.cpp: the orbits amplify each
  // step's rounding); 0 when none. No prediction goes below it.
  double amplified_round_off = 0.0;
  std::size_t pilot_states = 0;
  std::vector<PilotResult> pilots;  // one per candidate
  std::size_t chosen = 0;           // index into pilots
  std::uint64_t subdivision = 1;    // m: steps of the final run per step of time.dt
  double pilot_seconds = 0.0;
  EvaluationCounts pilot_evaluations;
  std::uint64_t pilot_state_steps = 0;
};

class ChoiceFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
// The pilots were stopped (options.stop_requested): nothing was chosen, nothing run.
class PilotsInterrupted : public ChoiceFailed {
 public:
  using ChoiceFailed::ChoiceFailed;
};

// Runs the pilots of `loaded` and returns the choice. Throws ChoiceFailed when no candidate is left (with every
// candidate's reason), PilotsInterrupted when interrupted (options.stop_requested). With measure "phase" and two or
// more degrees of freedom (one is integrable, and within a period its error may grow fast), when a usable
// candidate's phase error grew by more than 2^max_growth_exponent from t_p / 2 to t_p (the largest distance
// of its pilot pair at t_p k / 8 up to each), it grows exponentially: no prediction of the phase error at t_end
// holds, and the choice is made again by the energy (same tolerance) when the model has it (has_energy) and some
// candidate meets it there; else the phase pilots' choice stands.
SchemeChoice choose_scheme(const LoadedJob& loaded, const RunOptions& options);

// The warning to print before the run when the phase error grows exponentially: the tolerance is not promised, what
// chose the step, and what to use instead; "" otherwise.
std::string choice_warning(const SchemeChoice& choice);

// The run `loaded` would make with `choice`: the chosen integrator, the time grid divided by the subdivision m, and
// the strides counted in steps (output.every, checkpoint.every_steps, the Lyapunov strides) times m, so that every
// output stays at the same times; output.energy_every keeps counting the run's steps (1: H at every step).
void apply_choice(Job& job, const SchemeChoice& choice);

// The choice `recorded` (to_json's, as a checkpoint keeps it: checkpoint_file.hpp recorded_scheme_choice) put into
// the job as apply_choice puts it, without pilots: a resumed run continues with the interrupted run's choice. Throws
// CheckpointError, naming `checkpoint`, when it is not a choice this job could have made (another candidate list or
// grid).
void apply_recorded_choice(LoadedJob& loaded, const nlohmann::ordered_json& recorded,
                           const std::filesystem::path& checkpoint);

// summary.json's "scheme_choice": the tolerance, the candidates with their pilot measurements (or why they were
// left out), the choice, its predicted error and the pilots' cost.
nlohmann::ordered_json to_json(const SchemeChoice& choice);

// What `nonsep validate` says auto would try, one line; of a job not loaded (a formula job, not compiled), with
// the count of pilot states an upper bound when an energy shell will leave some out.
std::string describe_auto(const LoadedJob& loaded);
std::string describe_auto(const Job& job, const AutoModel& model, bool loaded);

}  // namespace nonsep::host
