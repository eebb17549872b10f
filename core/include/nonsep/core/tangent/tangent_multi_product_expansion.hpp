#pragma once
// The tangent map of the multi-product expansion, eqs. (mpe43) and (mpe63): the step is the linear combination
//   T^MPE(dt) x = sum_i c_i T^{k_i}(dt / k_i) x,
// so its derivative is the same combination of the terms' derivatives, each the product of k_i basic-step
// tangent maps (tangent_basic_step.hpp). Like the map itself it is not symplectic: M^T J M - J is of the size of
// the method's error term.
//
// The terms run one after the other from the same start and are combined as y_m + sum_k c_k (y_k - y_m), the
// order of MultiProductExpansion::step_term_by_term, which gives bit for bit the numbers of
// MultiProductExpansion::step (tests/core); the tangent vectors are combined in the same way. Tangent layout as
// in tangent_basic_step.hpp. Copies of the start, the running term and y_m (states and tangents) are kept as
// members and reused, so steady stepping does not allocate.
#include <vector>

#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/core/tangent/tangent_separable_composition.hpp"

namespace nonsep {

class TangentMultiProductExpansion {
 public:
  // The tangent map of `stepper`: its base's form and t2, its weights c_i.
  explicit TangentMultiProductExpansion(const MultiProductExpansion<SeparableBasicStep>& stepper)
      : base_(stepper.base()), weights_(stepper.weights()) {}

  int terms() const { return static_cast<int>(weights_.size()); }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  const HessianCounts& hessian_evaluations() const { return base_.hessian_evaluations(); }

  // As MultiProductExpansion::step, with the tangent vectors mapped along; errors as TangentBasicStep::step.
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    check_tangents_fit(x, tangents);
    const int m = terms();
    if (m == 1) {
      base_.step(model, x, tangents, dt);
      return;
    }
    start_ = x;
    start_tangents_ = tangents;
    for (int k = m; k >= 1; --k) {
      term_ = start_;
      term_tangents_ = start_tangents_;
      for (int r = 0; r < k; ++r) base_.step(model, term_, term_tangents_, dt / k);
      if (k == m) {
        last_ = term_;
        last_tangents_ = term_tangents_;
        x = term_;
        tangents = term_tangents_;
        continue;
      }
      const double c = weights_[static_cast<std::size_t>(k - 1)];
      accumulate(x.q(), c, term_.q(), last_.q());
      accumulate(x.p(), c, term_.p(), last_.p());
      accumulate(tangents.q(), c, term_tangents_.q(), last_tangents_.q());
      accumulate(tangents.p(), c, term_tangents_.p(), last_tangents_.p());
    }
  }

 private:
  static void accumulate(std::span<double> sum, double c, std::span<const double> y, std::span<const double> ym) {
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += c * (y[i] - ym[i]);
  }

  TangentSeparableComposition base_;
  std::vector<double> weights_;
  PhaseSpaceBatch start_, term_, last_;                             // states: the start, the running term, y_m
  PhaseSpaceBatch start_tangents_, term_tangents_, last_tangents_;  // their tangent vectors
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them.
inline TangentMultiProductExpansion tangent_map_of(const MultiProductExpansion<SeparableBasicStep>& stepper,
                                                   std::size_t) {
  return TangentMultiProductExpansion(stepper);
}

}  // namespace nonsep
