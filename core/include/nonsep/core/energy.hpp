#pragma once
// The energy of the Hamiltonian the integrators solve (paper, eq. (httv) and section III):
//   H_TTV = grad T(p) . (Hess V(q) grad T(p))      H_VVT = grad V(q) . (Hess T(p) grad V(q))
// Needs a model with Hessians (model.hpp). Not part of stepping: used for reporting and testing.
#include <span>
#include <vector>

#include "nonsep/core/chin_basic_step.hpp"

namespace nonsep {

class EnergyEvaluator {
 public:
  explicit EnergyEvaluator(HamiltonianForm form) : form_(form) {}

  // Writes H of each state of x into energies (size x.count()).
  template <ModelWithHessians M>
  void evaluate(const M& model, const PhaseSpaceBatch& x, std::span<double> energies) {
    check_batch_fits(model, x);
    if (energies.size() != x.count())
      throw InvalidArgument("energy output has " + std::to_string(energies.size()) + " entries for " +
                            std::to_string(x.count()) + " states");
    const std::size_t n = x.dimension();
    const std::size_t count = x.count();
    gradient_.resize(n * count);
    hessian_.resize(n * n * count);
    if (form_ == HamiltonianForm::TTV) {
      model.grad_T(x.p(), gradient_, count);
      model.hessian_V(x.q(), hessian_, count);
    } else {
      model.grad_V(x.q(), gradient_, count);
      model.hessian_T(x.p(), hessian_, count);
    }
    for (std::size_t b = 0; b < count; ++b) {
      const double* g = gradient_.data() + b * n;
      const double* h = hessian_.data() + b * n * n;
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        double row = 0.0;
        for (std::size_t j = 0; j < n; ++j) row += h[i * n + j] * g[j];
        sum += g[i] * row;
      }
      energies[b] = sum;
    }
  }

  template <ModelWithHessians M>
  double evaluate_one(const M& model, const PhaseSpaceBatch& x) {
    double e = 0.0;
    evaluate(model, x, std::span<double>(&e, 1));
    return e;
  }

 private:
  HamiltonianForm form_;
  std::vector<double> gradient_, hessian_;
};

}  // namespace nonsep
