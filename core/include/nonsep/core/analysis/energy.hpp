#pragma once
// The energy of the Hamiltonian the integrators solve (paper, eq. (httv) and section III):
//   H_TTV = grad T(p) . (Hess V(q) grad T(p))      H_VVT = grad V(q) . (Hess T(p) grad V(q))
// plus K(p) + U(q) when the model has a separable part (model.hpp, ModelWithSeparablePart; added after the product
// term, so a model without one gets the numbers of the product term alone).
// Needs a model with Hessians (model.hpp); one with Hessian-vector products is evaluated through them instead
// (hessian_products.hpp: one gradient and one product per state, O(n) numbers), and one that writes out the
// product term itself (ModelWithProductEnergy below: one pass per state) through that. Not part of stepping: used
// for reporting and testing. A model given by H itself (model.hpp, ModelWithGeneralHamiltonian) gives H by its
// value_H, in one batched call.
#include <algorithm>
#include <concepts>
#include <span>
#include <vector>

#include "nonsep/core/base/hessian_products.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

// A model that evaluates the product term of H itself (grad T . Hess V grad T for TTV, grad V . Hess T grad V for
// VVT, without K + U), for spans q, p (count*n numbers, read) and out (count numbers, written):
//   m.has_product_energy(form)                  whether it does, for that form, at run time
//   m.product_energy(form, q, p, out, count)    the product term of each state
// A sparse model's H then costs about one gradient, where a gradient and a product cost two passes over memory
// and a third for their dot product.
template <class M>
concept ModelWithProductEnergy = Model<M> &&
    requires(const M& m, HamiltonianForm form, std::span<const double> x, std::span<double> out, std::size_t count) {
  { m.has_product_energy(form) } -> std::convertible_to<bool>;
  m.product_energy(form, x, x, out, count);
};

class EnergyEvaluator {
 public:
  explicit EnergyEvaluator(HamiltonianForm form) : form_(form) {}

  // Writes H of each state of x into energies (size x.count()). Throws InvalidArgument for a batch that does not
  // fit the model or energies, or a model that is neither given by H nor of the product form with Hessians.
  template <class M>
  requires ModelWithHessians<M> || ModelWithGeneralHamiltonian<M>
  void evaluate(const M& model, const PhaseSpaceBatch& x, std::span<double> energies) {
    check_batch_fits(model, x);
    if (energies.size() != x.count())
      throw InvalidArgument("energy output has " + std::to_string(energies.size()) + " entries for " +
                            std::to_string(x.count()) + " states");
    if constexpr (ModelWithGeneralHamiltonian<M>)
      if (is_general_hamiltonian(model)) {
        model.value_H(x.q(), x.p(), energies, x.count());
        return;
      }
    if constexpr (ModelWithHessians<M>)
      evaluate_product_form(model, x, energies);
    else
      throw InvalidArgument("the energy: this model is neither given by H nor of the product form");
  }

  template <class M>
  requires ModelWithHessians<M> || ModelWithGeneralHamiltonian<M>
  double evaluate_one(const M& model, const PhaseSpaceBatch& x) {
    double e = 0.0;
    evaluate(model, x, std::span<double>(&e, 1));
    return e;
  }

 private:
  template <ModelWithHessians M>
  void evaluate_product_form(const M& model, const PhaseSpaceBatch& x, std::span<double> energies) {
    if constexpr (ModelWithProductEnergy<M>)
      if (model.has_product_energy(form_)) {
        model.product_energy(form_, x.q(), x.p(), energies, x.count());
        add_separable_part(model, x.q(), x.p(), energies, x.count());
        return;
      }
    if constexpr (ModelWithHessianProducts<M>)
      if (has_hessian_products(model)) {
        energy_by_products(model, form_, x.q(), x.p(), energies, x.count(), products_);
        add_separable_part(model, x.q(), x.p(), energies, x.count());
        return;
      }
    const std::size_t n = x.dimension();
    // A few states at a time, so that the Hessians take at most about hessian_values_per_call numbers (8 MiB)
    // whatever the batch: each state's H depends on that state alone, so the numbers are the same.
    const std::size_t per_call = std::max<std::size_t>(1, hessian_values_per_call / (n * n));
    for (std::size_t first = 0; first < x.count(); first += per_call) {
      const std::size_t count = std::min(per_call, x.count() - first);
      const auto q = x.q().subspan(first * n, count * n);
      const auto p = x.p().subspan(first * n, count * n);
      gradient_.resize(n * count);
      hessian_.resize(n * n * count);
      if (form_ == HamiltonianForm::TTV) {
        model.grad_T(p, gradient_, count);
        model.hessian_V(q, hessian_, count);
      } else {
        model.grad_V(q, gradient_, count);
        model.hessian_T(p, hessian_, count);
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
        energies[first + b] = sum;
      }
      add_separable_part(model, q, p, energies.subspan(first, count), count);
    }
  }

  template <class M>
  void add_separable_part(const M& model, std::span<const double> q, std::span<const double> p,
                          std::span<double> energies, std::size_t count) {
    if constexpr (ModelWithSeparablePart<M>) {
      separable_.resize(count);
      if (model.has_K()) {
        model.value_K(p, std::span<double>(separable_), count);
        for (std::size_t b = 0; b < count; ++b) energies[b] += separable_[b];
      }
      if (model.has_U()) {
        model.value_U(q, std::span<double>(separable_), count);
        for (std::size_t b = 0; b < count; ++b) energies[b] += separable_[b];
      }
    }
  }

  static constexpr std::size_t hessian_values_per_call = std::size_t{1} << 20;
  HamiltonianForm form_;
  std::vector<double> gradient_, hessian_, separable_;
  HessianProductScratch products_;
};

}  // namespace nonsep
