#pragma once
// A runtime-chosen integrator: one of the schemes of the catalogue (scheme_catalogue.hpp), built by the entry's
// factory from a scheme name, its options and the Hamiltonian form. This is what the host builds from a job file;
// code that knows its method at compile time uses ChinBasicStep, TripletComposition, MultiProductExpansion,
// TaoExtendedPhaseSpace or GaussLegendre directly.
//
// Comparators (family "comparator") need ModelWithThirdDerivatives: stepping one with a model type without them
// throws InvalidArgument (the host refuses such jobs before running). A stepper may keep private state per state
// (Tao's extended copy (x, y)): the Integrator hands the caller's batch changes on to it (compact() when states
// leave, step_part() when a step is redone state by state) and its state out and back as an opaque SchemeState
// (save_state(), restore_state(); scheme_state.hpp), so that the caller needs to know nothing of it.
#include <concepts>
#include <cstdint>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "nonsep/core/base/scheme_state.hpp"
#include "nonsep/core/schemes/scheme_catalogue.hpp"

namespace nonsep {

struct IntegratorSpec {
  std::string scheme =
      "basic";  // a catalogue entry's name: "basic", "triplet", "mpe", "tao", "implicit_midpoint", "gauss"
  Fraction order = Fraction(2, 3);             // Chin's schemes and tao
  double t2 = ChinCoefficients::default_t2();  // Chin's schemes
  HamiltonianForm form = HamiltonianForm::TTV;
  double omega = TaoExtendedPhaseSpace::default_omega;            // tao
  double stages = 2;                                              // gauss (whole number 1..3)
  double max_iterations = GaussLegendre::default_max_iterations;  // implicit_midpoint, gauss (whole number >= 1)
};

// The field of `spec` that holds the catalogue option `parameter` ("order": a Fraction; "t2", "omega", "stages",
// "max_iterations": a double). The one place where the catalogue's option names meet IntegratorSpec's fields: the
// job reader sets options through it and the host's checkpoint fingerprint reads every option of a scheme through
// it, so a new option reaches both. Throws std::logic_error for an option without a field (a programming error:
// the host's tests read every option of every catalogue entry).
using OptionField = std::variant<Fraction*, double*>;
OptionField option_field(IntegratorSpec& spec, const ParameterDescription& parameter);
// The value of that field, for readers (summaries, fingerprints): the same mapping as option_field.
std::variant<Fraction, double> option_value(const IntegratorSpec& spec, const ParameterDescription& parameter);
// A catalogue option's default (ParameterDescription::default_text) as its value. Throws std::logic_error when the
// text is not one (a programming error in the catalogue; the host's tests read every default).
std::variant<Fraction, double> default_option_value(const ParameterDescription& parameter);
// Sets option `parameter` of `spec` to `value` (a Fraction for the order, a double otherwise; std::logic_error for
// the other kind).
void set_option(IntegratorSpec& spec, const ParameterDescription& parameter,
                const std::variant<Fraction, double>& value);
// The spec of `scheme` with every option at its catalogue default (required options, without one, as IntegratorSpec
// has them), in form `form`.
IntegratorSpec default_spec(const Scheme& scheme, HamiltonianForm form = HamiltonianForm::TTV);

class Integrator {
 public:
  // Throws InvalidArgument naming the problem: t2 zero or not finite (Chin's schemes), unknown scheme (listing the
  // known ones), an option the scheme refuses (an order it does not have, listing the valid ones; omega, stages).
  explicit Integrator(const IntegratorSpec& spec);

  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    std::visit(
        [&](auto& stepper) {
          using S = std::decay_t<decltype(stepper)>;
          if constexpr (is_comparator_stepper<S>) {
            if constexpr (ModelWithThirdDerivatives<M>)
              stepper.step(model, x, dt);
            else
              throw InvalidArgument(needs_third_derivatives());
          } else {
            stepper.step(model, x, dt);
          }
        },
        stepper_);
  }

  // n steps of dt: bit for bit n calls of step(model, x, dt). The basic step, the triplet composition and the
  // multi-product expansion do their per-step bookkeeping once (ChinBasicStep::step_n, step_schedule_n and
  // step_expansion_n, through SeparableComposition), so that a model with a kernel takes the n steps in one call; the
  // other schemes take their steps one by one.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if (auto* basic = std::get_if<SeparableBasicStep>(&stepper_)) {
      basic->step_n(model, x, dt, n);
      return;
    }
    if (auto* triplet = std::get_if<TripletComposition<SeparableBasicStep>>(&stepper_)) {
      triplet->step_n(model, x, dt, n);
      return;
    }
    if (auto* mpe = std::get_if<MultiProductExpansion<SeparableBasicStep>>(&stepper_)) {
      mpe->step_n(model, x, dt, n);
      return;
    }
    for (std::uint64_t k = 0; k < n; ++k) step(model, x, dt);
  }

  // Makes the first-same-as-last gradient at x's point available (through the model's kernel when it has one:
  // ChinBasicStep::prime), for a caller that keeps a copy of this integrator to step again from x (the host's driver
  // redoing a chunk): the copy then starts from the gradient that steps through `model` would have used. Does nothing
  // for the schemes without one.
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (requires { stepper.prime(model, x); }) stepper.prime(model, x);
        },
        stepper_);
  }

  // Redoes one step for part of a batch: `part` holds states first .. first + part.count() - 1 of a batch of
  // `total` states whose step `before` (this integrator as it was before the step) was to take. A stepper with
  // private state per state takes that of those states from `before` and writes it back into its own; the others
  // step part as step() does.
  template <Model M>
  void step_part(const M& model, PhaseSpaceBatch& part, const Integrator& before, std::size_t first, std::size_t total,
                 double dt) {
    std::visit(
        [&](auto& stepper) {
          using S = std::decay_t<decltype(stepper)>;
          if constexpr (has_private_state<S>) {
            if constexpr (ModelWithThirdDerivatives<M>)
              stepper.step_part(model, part, std::get<S>(before.stepper_), first, total, dt);
            else
              throw InvalidArgument(needs_third_derivatives());
          } else {
            step(model, part, dt);
          }
        },
        stepper_);
  }

  // The states with retire[b] true leave the batch: a stepper with private state per state drops theirs.
  void compact(const std::vector<bool>& retire) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (has_private_state<std::decay_t<decltype(stepper)>>) stepper.compact(retire);
        },
        stepper_);
  }

  // The stepper's private state of the batch `states` it steps (empty for a stepper without one), and back: a
  // caller that checkpoints stores it (for any subset of the states, SchemeState::select) and restores it into an
  // integrator of the same spec stepping those states, which then goes on as if never stopped.
  SchemeState save_state(const PhaseSpaceBatch& states) const {
    return std::visit(
        [&](const auto& stepper) {
          if constexpr (has_private_state<std::decay_t<decltype(stepper)>>)
            return stepper.save_state(states);
          else
            return SchemeState{};
        },
        stepper_);
  }
  void restore_state(const SchemeState& state) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (has_private_state<std::decay_t<decltype(stepper)>>) stepper.restore_state(state);
        },
        stepper_);
  }
  // What the scheme reports about the steps this integrator took (Tao: omega and the largest copy distance); empty
  // for most schemes.
  std::vector<SchemeFigure> report() const {
    return std::visit(
        [](const auto& stepper) {
          if constexpr (has_private_state<std::decay_t<decltype(stepper)>>)
            return stepper.report();
          else
            return std::vector<SchemeFigure>{};
        },
        stepper_);
  }

  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& stepper) -> const EvaluationCounts& { return stepper.evaluations(); }, stepper_);
  }
  // The scheme's name, order, flags and family (a comparator's t2 is 0 and basic_steps_per_step 1).
  IntegratorDescription describe() const;
  bool is_comparator() const {
    return std::visit([](const auto& s) { return is_comparator_stepper<std::decay_t<decltype(s)>>; }, stepper_);
  }
  HamiltonianForm form() const { return form_; }
  const IntegratorSpec& spec() const { return spec_; }
  // The stepper the catalogue entry built (TangentIntegrator maps it to its tangent map).
  const SchemeStepper& stepper() const { return stepper_; }

 private:
  std::string needs_third_derivatives() const;
  template <class S>
  static constexpr bool has_private_state = requires(const S& stepper, const PhaseSpaceBatch& states) {
    { stepper.save_state(states) } -> std::same_as<SchemeState>;
  };

  IntegratorSpec spec_;
  HamiltonianForm form_;
  SchemeStepper stepper_;
};

}  // namespace nonsep
