#pragma once
// The energy and the gradient of the solved Hamiltonian from Hessian-vector products, O(n) numbers and (for a
// model whose products cost a few gradients) O(n) work per state, instead of the n x n Hessians of energy.hpp
// and hamiltonian_gradient.hpp, which call these when the model has products.
//
// A type M models nonsep::ModelWithHessianProducts when it is a Model (model.hpp) and moreover, for spans x, v
// (size count*n, read) and out (size count*n, written):
//   m.hvp_T(p, v, out, count)   writes sum_j d2T/dp_i dp_j v_j, i = 0..n-1, at each of the count momenta
//   m.hvp_V(q, v, out, count)   writes sum_j d2V/dq_i dq_j v_j, i = 0..n-1, at each of the count positions
// A type may have the members and still lack the products at run time (a plugin without hvp_T/hvp_V): it then
// has `bool has_hessian_vector_products() const`, which says so, and the callers take the dense path.
//
//   TTV: g = grad T(p), w = Hess V(q) g:   H = g . w,   dH/dp = 2 Hess T(p) w,   dH/dq = d3V(q, g)
//   VVT: g = grad V(q), w = Hess T(p) g:   H = g . w,   dH/dq = 2 Hess V(q) w,   dH/dp = d3T(p, g)
// (the same formulas as energy.hpp and hamiltonian_gradient.hpp, with each matrix met only as its product).
// A model may also give the inner product w with the third derivatives along the same g, in one call whose numbers
// are those of the two apart (nonsep::ModelWithThirdAndProduct: the SDK's automatic derivatives compute both in one
// pass); the gradient of H then takes it.
#include <algorithm>
#include <concepts>
#include <cstddef>
#include <span>
#include <vector>

#include "nonsep/core/base/model.hpp"

namespace nonsep {

template <class M>
concept ModelWithHessianProducts = Model<M> &&
    requires(const M& m, std::span<const double> x, std::span<const double> v, std::span<double> out,
             std::size_t count) {
  m.hvp_T(x, v, out, count);
  m.hvp_V(x, v, out, count);
};

// For spans x, u (size count*n, read) and out, product (size count*n, written):
//   m.d3V_with_product(q, u, out, product, count)   out = d3V(q, u), product = Hess V(q) u, at each position
//   m.d3T_with_product(p, u, out, product, count)   the same for T at each momentum
template <class M>
concept ModelWithThirdAndProduct = requires(const M& m, std::span<const double> x, std::span<const double> u,
                                            std::span<double> out, std::size_t count) {
  m.d3V_with_product(x, u, out, out, count);
  m.d3T_with_product(x, u, out, out, count);
};

// Whether `model` evaluates Hessian-vector products (its type has them and, where it says, the object too).
template <class M>
bool has_hessian_products(const M& model) {
  if constexpr (!ModelWithHessianProducts<M>)
    return false;
  else if constexpr (requires {
                       { model.has_hessian_vector_products() } -> std::convertible_to<bool>;
                     })
    return model.has_hessian_vector_products();
  else
    return true;
}

// Scratch of the product evaluations: 2 count*n numbers, kept between calls.
struct HessianProductScratch {
  std::vector<double> gradient, product;
  void resize(std::size_t size) {
    gradient.resize(size);
    product.resize(size);
  }
};

// g and w = (inner Hessian) g for the count states (q, p) of dimension n, into scratch.gradient and scratch.product.
template <ModelWithHessianProducts M>
void inner_hessian_product(const M& model, HamiltonianForm form, std::span<const double> q, std::span<const double> p,
                           std::size_t count, HessianProductScratch& scratch) {
  const std::size_t size = count * static_cast<std::size_t>(model.dimension());
  scratch.resize(size);
  const std::span<double> g(scratch.gradient.data(), size), w(scratch.product.data(), size);
  if (form == HamiltonianForm::TTV) {
    model.grad_T(p, g, count);
    model.hvp_V(q, g, w, count);
  } else {
    model.grad_V(q, g, count);
    model.hvp_T(p, g, w, count);
  }
}

// H of each of the count states into energies[0..count).
template <ModelWithHessianProducts M>
void energy_by_products(const M& model, HamiltonianForm form, std::span<const double> q, std::span<const double> p,
                        std::span<double> energies, std::size_t count, HessianProductScratch& scratch) {
  inner_hessian_product(model, form, q, p, count, scratch);
  const std::size_t n = model.dimension();
  for (std::size_t b = 0; b < count; ++b) {
    const double* g = scratch.gradient.data() + b * n;
    const double* w = scratch.product.data() + b * n;
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) sum += g[i] * w[i];
    energies[b] = sum;
  }
}

// dH/dq and dH/dp of each of the count states (spans of count*n numbers, checked by the caller).
template <class M>
requires ModelWithHessianProducts<M> && ModelWithThirdDerivatives<M>
void hamiltonian_gradient_by_products(const M& model, HamiltonianForm form, std::span<const double> q,
                                      std::span<const double> p, std::span<double> dH_dq, std::span<double> dH_dp,
                                      std::size_t count, HessianProductScratch& scratch) {
  if constexpr (ModelWithThirdAndProduct<M>) {
    const std::size_t size = count * static_cast<std::size_t>(model.dimension());
    scratch.resize(size);
    const std::span<double> g(scratch.gradient.data(), size), w(scratch.product.data(), size);
    if (form == HamiltonianForm::TTV) {
      model.grad_T(p, g, count);
      model.d3V_with_product(q, g, dH_dq, w, count);
      model.hvp_T(p, w, dH_dp, count);
      for (double& x : dH_dp) x *= 2.0;
    } else {
      model.grad_V(q, g, count);
      model.d3T_with_product(p, g, dH_dp, w, count);
      model.hvp_V(q, w, dH_dq, count);
      for (double& x : dH_dq) x *= 2.0;
    }
    return;
  }
  inner_hessian_product(model, form, q, p, count, scratch);
  const std::span<const double> g(scratch.gradient), w(scratch.product);
  if (form == HamiltonianForm::TTV) {
    model.hvp_T(p, w, dH_dp, count);
    model.d3V(q, g, dH_dq, count);
    for (double& x : dH_dp) x *= 2.0;
  } else {
    model.hvp_V(q, w, dH_dq, count);
    model.d3T(p, g, dH_dp, count);
    for (double& x : dH_dq) x *= 2.0;
  }
}

// The products X(x_b) v_(b*k+j) of k vectors per state with the Hessian at each of the count points (Hess V at q
// when `potential`, else Hess T at p), for the tangent maps: v and the result have the tangent layout of
// tangent_basic_step.hpp (vector j of state b at (b*k + j)*n). One batched call of count*k products; for k > 1
// each point is repeated k times in scratch.gradient. Returns the products (scratch.product).
template <ModelWithHessianProducts M>
std::span<const double> tangent_hessian_products(const M& model, bool potential, std::span<const double> point,
                                                 std::size_t count, std::size_t k, std::span<const double> v,
                                                 HessianProductScratch& scratch) {
  const std::size_t n = static_cast<std::size_t>(model.dimension()), size = count * k * n;
  scratch.resize(size);
  std::span<const double> points = point.first(count * n);
  if (k > 1) {
    for (std::size_t b = 0; b < count; ++b)
      for (std::size_t j = 0; j < k; ++j)
        std::copy(point.begin() + b * n, point.begin() + (b + 1) * n, scratch.gradient.begin() + (b * k + j) * n);
    points = scratch.gradient;
  }
  const std::span<double> out(scratch.product);
  if (potential)
    model.hvp_V(points, v.first(size), out, count * k);
  else
    model.hvp_T(points, v.first(size), out, count * k);
  return out;
}

}  // namespace nonsep
