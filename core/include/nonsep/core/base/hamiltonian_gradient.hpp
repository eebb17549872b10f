#pragma once
// The full gradient of the solved Hamiltonian, for the comparator schemes that integrate H directly (Tao's
// extended phase space, Gauss-Legendre collocation) instead of splitting T(p) + V(q) as Chin's schemes do.
//
//   TTV: H = T_i(p) V_ij(q) T_j(p)    dH/dq = d3V(q, grad T(p))        dH/dp = 2 Hess T(p) Hess V(q) grad T(p)
//   VVT: H = V_i(q) T_ij(p) V_j(q)    dH/dq = 2 Hess V(q) Hess T(p) grad V(q)    dH/dp = d3T(p, grad V(q))
//
// plus, for a model with a separable part (model.hpp), dH/dq += grad U(q) and dH/dp += grad K(p), added last so that
// a model without one gets the numbers of the product term alone;
// where d3V(q, u)_k = sum_ij d3V/dq_i dq_j dq_k u_i u_j (model.hpp, ModelWithThirdDerivatives). One evaluation
// costs the model one gradient, two Hessians and one third-derivative contraction per state, in four batched
// calls, and counts one grad_H per state (EvaluationCounts). A model with Hessian-vector products is evaluated
// through them instead (hessian_products.hpp): one gradient, two products and one third-derivative contraction,
// O(n) numbers per state. A model given by H itself (model.hpp, ModelWithGeneralHamiltonian) writes dH/dq and dH/dp
// in one batched call of its grad_H, counted the same way: so every scheme that integrates H sees one interface,
// whichever kind of model it steps.
//
// Layout: q, p, dH/dq and dH/dp are batches of `count` states of dimension n (component i of state b at b*n + i).
// Model exceptions propagate; the outputs are then unspecified.
#include <concepts>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/hessian_products.hpp"
#include "nonsep/core/base/model.hpp"

namespace nonsep {

// The directional derivative of grad H, for the tangent maps of the schemes that integrate H itself: the Hessian of
// the solved H (K + U included) times one tangent (dq, dp) per state (plugin_abi.h hvp_H writes out its formula,
// which reaches the fourth derivatives of the inner function: V in TTV, T in VVT). A type M models
// nonsep::ModelWithHamiltonianHessian when it is a Model and moreover, for spans x (size count*n, read) and out
// (size count*n, written):
//   m.hvp_H(form, q, p, dq, dp, out_q, out_p, count)   writes out_q = d(dH/dq), out_p = d(dH/dp) at each state
// (a model given by H itself ignores `form`). A type may have the member and still lack it at run time (a plugin
// without hvp_H): it then has `bool has_hamiltonian_hessian_products() const`, which says so.
template <class M>
concept ModelWithHamiltonianHessian = HamiltonianModel<M> &&
    requires(const M& m, HamiltonianForm form, std::span<const double> x, std::span<double> out, std::size_t count) {
  m.hvp_H(form, x, x, x, x, out, out, count);
};

// Whether `model` evaluates the directional derivative of grad H (its type has it and, where it says, the object).
template <class M>
bool has_hamiltonian_hessian(const M& model) {
  if constexpr (!ModelWithHamiltonianHessian<M>)
    return false;
  else if constexpr (requires {
                       { model.has_hamiltonian_hessian_products() } -> std::convertible_to<bool>;
                     })
    return model.has_hamiltonian_hessian_products();
  else
    return true;
}

// Throws InvalidArgument unless `model` evaluates the directional derivative of grad H, naming what is missing: the
// tangent map of `scheme` needs it.
template <class M>
void require_hamiltonian_hessian(const M& model, const std::string& scheme) {
  if (!has_hamiltonian_hessian(model))
    throw InvalidArgument("the tangent map of the scheme '" + scheme +
                          "' needs the directional derivative of grad H, which this model lacks (the plugin entry "
                          "hvp_H of plugin ABI version 5: rebuild the plugin against the installed SDK)");
}

class HamiltonianGradient {
 public:
  explicit HamiltonianGradient(HamiltonianForm form = HamiltonianForm::TTV) : form_(form) {}

  HamiltonianForm form() const { return form_; }
  const EvaluationCounts& evaluations() const { return evaluations_; }
  void add_evaluations(const EvaluationCounts& counts) { evaluations_ += counts; }

  // Writes dH/dq and dH/dp at each of the count points (q, p). All four spans hold at least count*n numbers.
  // Throws InvalidArgument when a span is too short, or for a model that is neither of the product form with third
  // derivatives nor given by H.
  template <HamiltonianModel M>
  void evaluate(const M& model, std::span<const double> q, std::span<const double> p, std::span<double> dH_dq,
                std::span<double> dH_dp, std::size_t count) {
    const auto n = static_cast<std::size_t>(model.dimension());
    const std::size_t size = n * count;
    if (q.size() < size || p.size() < size || dH_dq.size() < size || dH_dp.size() < size)
      throw InvalidArgument("the gradient of H of " + std::to_string(count) + " states of dimension " +
                            std::to_string(n) + " needs spans of " + std::to_string(size) + " numbers");
    q = q.first(size);
    p = p.first(size);
    dH_dq = dH_dq.first(size);
    dH_dp = dH_dp.first(size);
    if constexpr (ModelWithGeneralHamiltonian<M>) {
      if (is_general_hamiltonian(model)) {
        model.grad_H(q, p, dH_dq, dH_dp, count);
        evaluations_.grad_H += count;
        return;
      }
    }
    if constexpr (ModelWithThirdDerivatives<M>)
      evaluate_product_form(model, q, p, dH_dq, dH_dp, count);
    else
      throw InvalidArgument("the gradient of H: this model is neither given by H nor of the product form");
  }

 private:
  // evaluate() of a product-form model (spans checked and cut to size).
  template <ModelWithThirdDerivatives M>
  void evaluate_product_form(const M& model, std::span<const double> q, std::span<const double> p,
                             std::span<double> dH_dq, std::span<double> dH_dp, std::size_t count) {
    const auto n = static_cast<std::size_t>(model.dimension());
    const std::size_t size = n * count;
    if constexpr (ModelWithHessianProducts<M>) {
      if (has_hessian_products(model)) {
        hamiltonian_gradient_by_products(model, form_, q, p, dH_dq, dH_dp, count, products_);
        product_.resize(size);
        add_separable_part(model, q, p, dH_dq, dH_dp, size, count);
        evaluations_.grad_H += count;
        return;
      }
    }
    gradient_.resize(size);
    product_.resize(size);
    outer_hessian_.resize(size * n);
    inner_hessian_.resize(size * n);
    // TTV: the gradient is grad T(p), contracted with Hess V(q) (inner) then Hess T(p) (outer); the third
    // derivative is V's, at q. VVT: every role swapped.
    const bool ttv = form_ == HamiltonianForm::TTV;
    if (ttv) {
      model.grad_T(p, std::span<double>(gradient_), count);
      model.hessian_V(q, std::span<double>(inner_hessian_), count);
      model.hessian_T(p, std::span<double>(outer_hessian_), count);
      model.d3V(q, std::span<const double>(gradient_), dH_dq, count);
    } else {
      model.grad_V(q, std::span<double>(gradient_), count);
      model.hessian_T(p, std::span<double>(inner_hessian_), count);
      model.hessian_V(q, std::span<double>(outer_hessian_), count);
      model.d3T(p, std::span<const double>(gradient_), dH_dp, count);
    }
    multiply(inner_hessian_, gradient_, product_, n, count, 1.0);
    multiply(outer_hessian_, product_, ttv ? dH_dp : dH_dq, n, count, 2.0);
    add_separable_part(model, q, p, dH_dq, dH_dp, size, count);
    evaluations_.grad_H += count;
  }

  template <class M>
  void add_separable_part(const M& model, std::span<const double> q, std::span<const double> p, std::span<double> dH_dq,
                          std::span<double> dH_dp, std::size_t size, std::size_t count) {
    if constexpr (ModelWithSeparablePart<M>) {
      if (model.has_U()) {
        model.grad_U(q, std::span<double>(product_), count);
        for (std::size_t i = 0; i < size; ++i) dH_dq[i] += product_[i];
      }
      if (model.has_K()) {
        model.grad_K(p, std::span<double>(product_), count);
        for (std::size_t i = 0; i < size; ++i) dH_dp[i] += product_[i];
      }
    }
  }

  // out_b = factor * A_b u_b for each state b (A row-major n x n per state).
  static void multiply(std::span<const double> a, std::span<const double> u, std::span<double> out, std::size_t n,
                       std::size_t count, double factor) {
    if (n == 1) {  // the loop below with its inner sums unrolled, so that it vectorizes (the same operations)
      for (std::size_t b = 0; b < count; ++b) out[b] = factor * (0.0 + a[b] * u[b]);
      return;
    }
    for (std::size_t b = 0; b < count; ++b) {
      const double* m = a.data() + b * n * n;
      const double* v = u.data() + b * n;
      for (std::size_t i = 0; i < n; ++i) {
        double sum = 0.0;
        for (std::size_t j = 0; j < n; ++j) sum += m[i * n + j] * v[j];
        out[b * n + i] = factor * sum;
      }
    }
  }

  HamiltonianForm form_;
  EvaluationCounts evaluations_;
  std::vector<double> gradient_, product_, outer_hessian_, inner_hessian_;
  HessianProductScratch products_;
};

}  // namespace nonsep
