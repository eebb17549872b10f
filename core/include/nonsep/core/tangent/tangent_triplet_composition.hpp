#pragma once
// The tangent map of the triplet composition, eqs. (sym43) and (sym63): the chain rule through the 3^levels basic
// steps of a step, which is the product of their tangent maps (tangent_separable_composition.hpp) taken in the order
// the composition runs them. The schedule of step sizes is TripletComposition::for_each_basic_step, the one the plain
// composition runs, so the states get bit for bit the numbers of TripletComposition::step, and the tangent map is
// symplectic (a product of symplectic maps). Tangent layout as in tangent_basic_step.hpp.
#include <span>
#include <vector>

#include "nonsep/core/schemes/triplet_composition.hpp"
#include "nonsep/core/tangent/tangent_separable_composition.hpp"

namespace nonsep {

class TangentTripletComposition {
 public:
  // The tangent map of `stepper`: its base's form and t2, its number of levels.
  explicit TangentTripletComposition(const TripletComposition<SeparableBasicStep>& stepper)
      : base_(stepper.base()), levels_(stepper.levels()) {}

  int levels() const { return levels_; }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  const HessianCounts& hessian_evaluations() const { return base_.hessian_evaluations(); }

  // As TripletComposition::step, with the tangent vectors mapped along; errors as TangentBasicStep::step.
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    check_step_size(dt);
    TripletComposition<SeparableBasicStep>::for_each_basic_step(
        levels_, dt, [&](double basic_dt) { base_.step(model, x, tangents, basic_dt); });
  }

  // n composed steps of dt through the model's tangent kernel, the 3^levels basic steps of each as one schedule
  // (TangentSeparableComposition::step_kernel_n); false (nothing done) without one.
  template <ModelWithHessians M>
  bool step_kernel_n(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt, std::uint64_t n) {
    check_step_size(dt);
    schedule_.clear();
    TripletComposition<SeparableBasicStep>::for_each_basic_step(
        levels_, dt, [&](double basic_dt) { schedule_.push_back(basic_dt); });
    return base_.step_kernel_n(model, x, tangents, std::span<const double>(schedule_), n);
  }

 private:
  TangentSeparableComposition base_;
  int levels_;
  std::vector<double> schedule_;  // step_kernel_n's basic step sizes, kept for their storage
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them.
inline TangentTripletComposition tangent_map_of(const TripletComposition<SeparableBasicStep>& stepper, std::size_t) {
  return TangentTripletComposition(stepper);
}

}  // namespace nonsep
