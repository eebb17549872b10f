#pragma once
// The tangent map of the separable composition (separable_composition.hpp): the basic step's tangent map
// (tangent_basic_step.hpp) between the linearised exact flows of K(p) and U(q),
//   drift q <- q + h grad K(p)   has   dq <- dq + h Hess K(p) dp
//   kick  p <- p - h grad U(q)   has   dp <- dp - h Hess U(q) dq
// each at the point its flow started from (which the flow leaves unchanged), in the order of
// SeparableComposition::for_each_flow, so the states get bit for bit the numbers of SeparableComposition::step and
// the map is symplectic (a product of shears). A model without a separable part gets TangentBasicStep's numbers.
// Tangent layout as in tangent_basic_step.hpp. Hess K and Hess U are evaluated at every separable flow, counted
// per state in hessian_evaluations() (hessian_K, hessian_U) beside the basic step's.
#include <span>
#include <vector>

#include "nonsep/core/schemes/separable_composition.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"

namespace nonsep {

class TangentSeparableComposition {
 public:
  explicit TangentSeparableComposition(const SeparableBasicStep& stepper = SeparableBasicStep())
      : base_(ChinBasicStep(stepper.form(), stepper.coefficients().t2)) {}

  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const {
    total_ = base_.evaluations();
    total_.grad_K = separable_.grad_K;
    total_.grad_U = separable_.grad_U;
    return total_;
  }
  const HessianCounts& hessian_evaluations() const {
    hessians_ = base_.hessian_evaluations();
    hessians_.hessian_K = separable_hessians_.hessian_K;
    hessians_.hessian_U = separable_hessians_.hessian_U;
    return hessians_;
  }

  // TangentBasicStep::step_kernel_n for a model without a separable part; false (nothing done) for one with it.
  template <ModelWithHessians M>
  bool step_kernel_n(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::span<const double> dts,
                     std::uint64_t n) {
    return !has_separable_part(model) && base_.step_kernel_n(model, x, tangents, dts, n);
  }

  // As SeparableComposition::step, with the tangent vectors mapped along; errors as TangentBasicStep::step.
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    if (!has_separable_part(model)) {
      base_.step(model, x, tangents, dt);
      return;
    }
    check_batch_fits(model, x);
    check_step_size(dt);
    const std::size_t k = check_tangents_fit(x, tangents);
    SeparableBasicStep::for_each_flow(
        has_K(model), has_U(model), [&](SeparableFlow f) { flow(model, x, tangents, k, f, dt); },
        [&] { base_.step(model, x, tangents, dt); });
  }

 private:
  template <ModelWithHessians M>
  void flow(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::size_t k, SeparableFlow f, double dt) {
    if constexpr (ModelWithSeparablePart<M>) {
      const std::size_t count = x.count(), n = x.dimension();
      gradient_.resize(x.size());
      hessian_.resize(x.size() * n);
      if (f.kick) {
        model.grad_U(std::as_const(x).q(), std::span<double>(gradient_), count);
        model.hessian_U(std::as_const(x).q(), std::span<double>(hessian_), count);
        separable_.grad_U += count;
        separable_hessians_.hessian_U += count;
      } else {
        model.grad_K(std::as_const(x).p(), std::span<double>(gradient_), count);
        model.hessian_K(std::as_const(x).p(), std::span<double>(hessian_), count);
        separable_.grad_K += count;
        separable_hessians_.hessian_K += count;
      }
      SeparableBasicStep::shift(f.kick ? x.p() : x.q(), gradient_, f, std::span<const double>(&dt, 1), count, n);
      const double h = (f.kick ? -1.0 : 1.0) * f.fraction * dt;
      double* moved = (f.kick ? tangents.p() : tangents.q()).data();
      const double* driver = (f.kick ? std::as_const(tangents).q() : std::as_const(tangents).p()).data();
      for (std::size_t b = 0; b < count; ++b) {
        const double* matrix = hessian_.data() + b * n * n;
        for (std::size_t j = 0; j < k; ++j) {
          const double* in = driver + (b * k + j) * n;
          double* out = moved + (b * k + j) * n;
          for (std::size_t r = 0; r < n; ++r) {
            double sum = 0.0;
            for (std::size_t c = 0; c < n; ++c) sum += matrix[r * n + c] * in[c];
            out[r] += h * sum;
          }
        }
      }
    }
  }

  TangentBasicStep base_;
  EvaluationCounts separable_;
  HessianCounts separable_hessians_;
  mutable EvaluationCounts total_;
  mutable HessianCounts hessians_;
  std::vector<double> gradient_, hessian_;
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them.
inline TangentSeparableComposition tangent_map_of(const SeparableBasicStep& stepper, std::size_t) {
  return TangentSeparableComposition(stepper);
}

}  // namespace nonsep
