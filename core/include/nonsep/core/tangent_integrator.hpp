#pragma once
// A runtime-chosen tangent stepper: the tangent map of the integrator an IntegratorSpec describes (the scheme of
// a job file, built by its catalogue entry), for diagnostics that follow tangent vectors (lyapunov_exponents.hpp,
// megno.hpp). The states are stepped bit for bit as Integrator(spec) steps them.
#include <string>
#include <type_traits>
#include <variant>

#include "nonsep/core/integrator.hpp"
#include "nonsep/core/tangent_multi_product_expansion.hpp"
#include "nonsep/core/tangent_separable_composition.hpp"
#include "nonsep/core/tangent_triplet_composition.hpp"

namespace nonsep {

// The tangent map of each stepper type a catalogue entry builds (SchemeStepper): the states stepped bit for bit as
// the stepper steps them.
inline TangentSeparableComposition tangent_map_of(const SeparableBasicStep& stepper) {
  return TangentSeparableComposition(stepper);
}
inline TangentTripletComposition tangent_map_of(const TripletComposition<SeparableBasicStep>& stepper) {
  return TangentTripletComposition(stepper);
}
inline TangentMultiProductExpansion tangent_map_of(const MultiProductExpansion<SeparableBasicStep>& stepper) {
  return TangentMultiProductExpansion(stepper);
}

// Whether the scheme `spec` names has a tangent map (TangentIntegrator builds one): the one place that says so, for
// the job reader and scheme "auto". Throws InvalidArgument as Integrator(spec) does.
inline bool has_tangent_map(const IntegratorSpec& spec) {
  return std::visit([](const auto& stepper) { return !is_comparator_stepper<std::decay_t<decltype(stepper)>>; },
                    Integrator(spec).stepper());
}

class TangentIntegrator {
 public:
  // Throws InvalidArgument as Integrator(spec) does (bad t2, unknown scheme, an order the scheme does not have),
  // and for a comparator scheme (tao, implicit_midpoint, gauss), which has no tangent map.
  explicit TangentIntegrator(const IntegratorSpec& spec) : spec_(spec), stepper_(make(spec)) {}

  const IntegratorSpec& spec() const { return spec_; }

  // Advances x by dt and maps the tangent vectors (layout of tangent_basic_step.hpp); errors as
  // TangentBasicStep::step.
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    std::visit([&](auto& stepper) { stepper.step(model, x, tangents, dt); }, stepper_);
  }
  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& s) -> const EvaluationCounts& { return s.evaluations(); }, stepper_);
  }
  const HessianCounts& hessian_evaluations() const {
    return std::visit([](const auto& s) -> const HessianCounts& { return s.hessian_evaluations(); }, stepper_);
  }

 private:
  using Stepper = std::variant<TangentSeparableComposition, TangentTripletComposition, TangentMultiProductExpansion>;
  // Built by the catalogue, through Integrator, and mapped to its tangent map.
  static Stepper make(const IntegratorSpec& spec) {
    return std::visit(
        [&](const auto& stepper) -> Stepper {
          if constexpr (is_comparator_stepper<std::decay_t<decltype(stepper)>>)
            throw InvalidArgument("the comparator scheme '" + spec.scheme +
                                  "' has no tangent map: Lyapunov exponents and MEGNO need a Chin scheme "
                                  "(basic, triplet, mpe)");
          else
            return tangent_map_of(stepper);
        },
        Integrator(spec).stepper());
  }

  IntegratorSpec spec_;
  Stepper stepper_;
};

}  // namespace nonsep
