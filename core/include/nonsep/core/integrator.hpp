#pragma once
// A runtime-chosen integrator: one of the schemes of the catalogue (scheme_catalogue.hpp), built by the entry's
// factory from a scheme name, its options and the Hamiltonian form. This is what the host builds from a job file;
// code that knows its method at compile time uses ChinBasicStep, TripletComposition, MultiProductExpansion,
// TaoExtendedPhaseSpace or GaussLegendre directly.
//
// Comparators (family "comparator") need ModelWithThirdDerivatives: stepping one with a model type without them
// throws InvalidArgument (the host refuses such jobs before running). Tao's stepper holds the extended copy (x, y)
// of each state: the Integrator keeps it aligned with the batch the caller steps (compact() when states leave,
// step_part() when a step is redone state by state) and tracks the largest copy distance seen.
#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "nonsep/core/scheme_catalogue.hpp"

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
            if constexpr (ModelWithThirdDerivatives<M>) {
              stepper.step(model, x, dt);
              if constexpr (std::is_same_v<S, TaoExtendedPhaseSpace>) track_copy_distance(stepper, x);
            } else {
              throw InvalidArgument(needs_third_derivatives());
            }
          } else {
            stepper.step(model, x, dt);
          }
        },
        stepper_);
  }

  // n steps of dt: bit for bit n calls of step(model, x, dt). The basic step does its per-step bookkeeping once
  // (ChinBasicStep::step_n, through SeparableComposition::step_n); the other schemes take their steps one by one.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if (auto* basic = std::get_if<SeparableBasicStep>(&stepper_)) {
      basic->step_n(model, x, dt, n);
      return;
    }
    for (std::uint64_t k = 0; k < n; ++k) step(model, x, dt);
  }

  // Redoes one step for part of a batch: `part` holds states first .. first + part.count() - 1 of a batch of
  // `total` states whose step `before` (this integrator as it was before the step) was to take. For Tao the
  // copies of those states come from `before` and are written back into this integrator's copies; the other
  // schemes hold nothing per state and step part as step() does.
  template <Model M>
  void step_part(const M& model, PhaseSpaceBatch& part, const Integrator& before, std::size_t first, std::size_t total,
                 double dt) {
    auto* tao = std::get_if<TaoExtendedPhaseSpace>(&stepper_);
    if (!tao) {
      step(model, part, dt);
      return;
    }
    if constexpr (ModelWithThirdDerivatives<M>) {
      const auto& held = std::get<TaoExtendedPhaseSpace>(before.stepper_).copies();
      PhaseSpaceBatch copies = held.count() == total ? slice(held, first, part.count()) : part;
      tao->step(model, part, copies, dt);
      PhaseSpaceBatch all = tao->copies().count() == total ? tao->copies() : PhaseSpaceBatch(part.dimension(), total);
      for (std::size_t b = 0; b < part.count(); ++b) {
        std::copy(copies.q(b).begin(), copies.q(b).end(), all.q(first + b).begin());
        std::copy(copies.p(b).begin(), copies.p(b).end(), all.p(first + b).begin());
      }
      tao->restore_copies(std::move(all));
      track_copy_distance(*tao, part, &copies);
    } else {
      throw InvalidArgument(needs_third_derivatives());
    }
  }

  // The states with retire[b] true leave the batch: Tao drops their copies (nothing for the other schemes).
  void compact(const std::vector<bool>& retire) {
    if (auto* tao = std::get_if<TaoExtendedPhaseSpace>(&stepper_); tao && tao->copies().count() == retire.size())
      tao->compact_copies(retire);
  }

  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& stepper) -> const EvaluationCounts& { return stepper.evaluations(); }, stepper_);
  }
  // The scheme's name, order, flags and family (a comparator's t2 is 0 and basic_steps_per_step 1).
  IntegratorDescription describe() const;
  bool is_comparator() const {
    return std::visit([](const auto& s) { return is_comparator_stepper<std::decay_t<decltype(s)>>; }, stepper_);
  }
  // Tao only: the largest |(q, p) - (x, y)| over the states and steps this integrator took (0 before a step).
  double max_copy_distance() const { return max_copy_distance_; }
  // Tao only: the extended copies of the batch's states, or nullptr (other schemes; Tao before its first step).
  const PhaseSpaceBatch* copies() const {
    const auto* tao = std::get_if<TaoExtendedPhaseSpace>(&stepper_);
    return tao && tao->copies().count() > 0 ? &tao->copies() : nullptr;
  }
  // Tao only (nothing for the other schemes): continues from a checkpoint, with these copies of the batch's states
  // and the largest copy distance of the steps before it, so that the run goes on as if never stopped.
  void restore_copies(PhaseSpaceBatch copies, double max_copy_distance) {
    if (auto* tao = std::get_if<TaoExtendedPhaseSpace>(&stepper_)) {
      tao->restore_copies(std::move(copies));
      max_copy_distance_ = max_copy_distance;
    }
  }
  HamiltonianForm form() const { return form_; }
  const IntegratorSpec& spec() const { return spec_; }
  // The stepper the catalogue entry built (TangentIntegrator maps it to its tangent map).
  const SchemeStepper& stepper() const { return stepper_; }

 private:
  std::string needs_third_derivatives() const;
  static PhaseSpaceBatch slice(const PhaseSpaceBatch& x, std::size_t first, std::size_t count) {
    PhaseSpaceBatch out(x.dimension(), count);
    for (std::size_t b = 0; b < count; ++b) {
      std::copy(x.q(first + b).begin(), x.q(first + b).end(), out.q(b).begin());
      std::copy(x.p(first + b).begin(), x.p(first + b).end(), out.p(b).begin());
    }
    return out;
  }
  void track_copy_distance(const TaoExtendedPhaseSpace& tao, const PhaseSpaceBatch& x,
                           const PhaseSpaceBatch* copies = nullptr) {
    distances_.resize(x.count());
    TaoExtendedPhaseSpace::copy_distance(x, copies ? *copies : tao.copies(), distances_);
    for (double d : distances_) max_copy_distance_ = std::max(max_copy_distance_, d);
  }

  IntegratorSpec spec_;
  HamiltonianForm form_;
  SchemeStepper stepper_;
  double max_copy_distance_ = 0.0;
  std::vector<double> distances_;
};

}  // namespace nonsep
