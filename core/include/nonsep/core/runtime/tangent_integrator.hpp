#pragma once
// A runtime-chosen tangent stepper: the tangent map of the integrator a spec describes (the scheme of a job
// file, built by BasicIntegrator over a list of schemes; TangentIntegrator over the shipped ones), for diagnostics that
// follow tangent vectors (lyapunov_exponents.hpp, megno.hpp). The states are stepped bit for bit as Integrator(spec)
// steps them. Every scheme has one: Chin's (tangent_separable_composition.hpp and its wrappers), Gauss-Legendre and the
// implicit midpoint rule (tangent_gauss_legendre.hpp), Tao's extended phase space
// (tangent_tao_extended_phase_space.hpp); the comparators' need a model with the directional derivative of grad H
// (ModelWithHamiltonianHessian, hamiltonian_gradient.hpp). A stepper's tangent map is what tangent_map_of(stepper,
// vectors_per_state) returns (an overload beside each tangent stepper, found by argument-dependent lookup). As
// Integrator does for the plain steppers, it hands a runner's batch changes on to a tangent stepper with private state
// per state (Tao's copies and their tangents: step_part(), compact()) and that state out and back as an opaque
// SchemeState (save_state(), restore_state()).
#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"

namespace nonsep {

// Whether the scheme `spec` names has a tangent map (TangentIntegrator builds one): the one place that says so, for
// the job reader and scheme "auto". Every scheme of the catalogue has one; a comparator's needs the model's
// directional derivative of grad H besides (the job reader checks the plugin for it). Read from the scheme's stepper
// type without building one; throws InvalidArgument as Integrator(spec) does.
template <class... Schemes>
bool has_tangent_map(const BasicIntegratorSpec<Schemes...>& spec) {
  BasicIntegrator<Schemes...>::describe(spec);
  bool has = false;
  with_scheme_at<Schemes...>(spec.index_of(spec.scheme), [&](auto scheme) {
    using S = typename decltype(scheme)::type::Stepper;
    has = requires(const S& stepper) { tangent_map_of(stepper, std::size_t{1}); };
  });
  return has;
}

// The tangent map type of stepper type S, or void without one.
template <class S>
struct TangentMapOf {
  using type = void;
};
template <class S>
requires requires(const S& stepper) { tangent_map_of(stepper, std::size_t{1}); }
struct TangentMapOf<S> {
  using type = decltype(tangent_map_of(std::declval<const S&>(), std::size_t{1}));
};

template <IntegrationScheme... Schemes>
class BasicTangentIntegrator {
 public:
  using Spec = BasicIntegratorSpec<Schemes...>;

  // Throws InvalidArgument as Integrator(spec) does (bad t2, unknown scheme, an order the scheme does not have).
  // `vectors_per_state` (k) sizes the private state of a scheme that keeps one before its first step (save_state).
  // A scheme without a tangent map: InvalidArgument naming it.
  explicit BasicTangentIntegrator(const Spec& spec, std::size_t vectors_per_state = 0)
      : spec_(spec), stepper_(make(spec, vectors_per_state)) {}

  const Spec& spec() const { return spec_; }

  // Advances x by dt and maps the tangent vectors (layout of tangent_basic_step.hpp); errors as
  // TangentBasicStep::step. A comparator with a model without third derivatives or without the directional derivative
  // of grad H: InvalidArgument naming what is missing.
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    std::visit(
        [&](auto& stepper) {
          if constexpr (requires { stepper.step(model, x, tangents, dt); })
            stepper.step(model, x, tangents, dt);
          else
            throw InvalidArgument(lacks_hamiltonian_hessian());
        },
        stepper_);
  }

  // n steps of dt through the model's tangent kernel (a Chin scheme of basic or triplet steps and a plugin with
  // chin_tangent_steps), bit for bit n calls of step() for a kernel compiled as the evaluation path; false (nothing
  // done) when the scheme or the model has none: the caller then calls step().
  template <ModelWithHessians M>
  bool step_kernel_n(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt, std::uint64_t n) {
    if (auto* basic = std::get_if<TangentSeparableComposition>(&stepper_)) {
      check_step_size(dt);
      return basic->step_kernel_n(model, x, tangents, std::span<const double>(&dt, 1), n);
    }
    if (auto* triplet = std::get_if<TangentTripletComposition>(&stepper_))
      return triplet->step_kernel_n(model, x, tangents, dt, n);
    return false;
  }

  // Redoes one step for part of a batch, as Integrator::step_part: `part` and `part_tangents` hold states first ..
  // first + part.count() - 1 of a batch of `total` states (and their vectors) whose step `before` (this integrator
  // as it was before the step) was to take.
  template <ModelWithHessians M>
  void step_part(const M& model, PhaseSpaceBatch& part, PhaseSpaceBatch& part_tangents,
                 const BasicTangentIntegrator& before, std::size_t first, std::size_t total, double dt) {
    std::visit(
        [&](auto& stepper) {
          using S = std::decay_t<decltype(stepper)>;
          if constexpr (!StepperWithPrivateState<S>)
            step(model, part, part_tangents, dt);
          else if constexpr (requires { stepper.step_part(model, part, part_tangents, stepper, first, total, dt); })
            stepper.step_part(model, part, part_tangents, std::get<S>(before.stepper_), first, total, dt);
          else
            throw InvalidArgument(lacks_hamiltonian_hessian());
        },
        stepper_);
  }

  // The states with retire[b] true leave the batch (with their vectors).
  void compact(const std::vector<bool>& retire) { compact_private_state(stepper_, retire); }
  // The private state of the batch `states` (empty for most schemes), and back, as Integrator's.
  SchemeState save_state(const PhaseSpaceBatch& states) const { return save_private_state(stepper_, states); }
  void restore_state(const SchemeState& state) { restore_private_state(stepper_, state); }
  std::vector<SchemeFigure> report() const { return private_report(stepper_); }

  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& s) -> const EvaluationCounts& { return s.evaluations(); }, stepper_);
  }
  const HessianCounts& hessian_evaluations() const {
    return std::visit([](const auto& s) -> const HessianCounts& { return s.hessian_evaluations(); }, stepper_);
  }

 private:
  using Stepper = DistinctVariant<typename TangentMapOf<typename Schemes::Stepper>::type...>;

  // Built by the scheme, through BasicIntegrator, and mapped to its tangent map.
  static Stepper make(const Spec& spec, std::size_t k) {
    return std::visit(
        [&](const auto& stepper) -> Stepper {
          if constexpr (requires { tangent_map_of(stepper, k); })
            return tangent_map_of(stepper, k);
          else
            throw InvalidArgument("the scheme '" + spec.scheme + "' has no tangent map");
        },
        BasicIntegrator<Schemes...>(spec).stepper());
  }
  std::string lacks_hamiltonian_hessian() const {
    return "the tangent map of the scheme '" + spec_.scheme +
           "' needs a model with third derivatives and the directional derivative of grad H (the plugin entry hvp_H "
           "of plugin ABI version 5)";
  }

  Spec spec_;
  Stepper stepper_;
};

using TangentIntegrator = WithShippedSchemes<BasicTangentIntegrator>;

// The names and sizes of the private state of a run of `spec` with `tangent_vectors` vectors per state (0: the plain
// Integrator's) in dimension n, with no values: what a checkpoint reader fills.
inline SchemeState scheme_state_layout(const IntegratorSpec& spec, std::size_t tangent_vectors, std::size_t n) {
  const PhaseSpaceBatch none(n, 0);
  return tangent_vectors > 0 ? TangentIntegrator(spec, tangent_vectors).save_state(none)
                             : Integrator(spec).save_state(none);
}

}  // namespace nonsep
