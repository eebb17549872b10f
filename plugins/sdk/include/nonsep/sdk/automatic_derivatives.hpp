#pragma once
// The derivatives ModelAdapter computes by forward-mode automatic differentiation (dual.hpp) of a scalar function
// f written for any scalar type, at one point x of n <= K components. K is the capacity (the model's dimension or
// max_dimension); all storage is std::array on the stack, so none of these allocates.
//
//   gradient_by_dual            grad f(x)                   one pass of Dual<double, K>
//   hessian_by_dual             the n x n Hessian, row-major  n passes of Dual<Dual<double, K>, 1>, column j seeded
//                                                            with e_j in the outer slot
//   directional_third_by_dual   out_k = sum_ij f_ijk(x) u_i u_j, the gradient of u^T H(x) u: mixed_third_by_dual
//                               with a = b = u, one pass of Dual<Dual<Dual<double, K>, 1>, 1>, so the e1 e2 part is
//                               d^2/ds dt f(x + (s + t) u) with its gradient in x inside. 4 (K+1) doubles per
//                               number: cheaper than differencing n Hessian passes, and no Hessian is formed.
//   hessian_vector_by_dual      out = H(x) v, one column pass of hessian_by_dual with the outer slot seeded with v
//                               instead of e_j: the cost of a single Hessian column (and grad f alongside, on
//                               request).
//   mixed_third_by_dual         out_k = sum_ij f_kij(x) a_i b_j, one pass of ThirdDerivativeDual<K> with the outer
//                               slots seeded with a and b
//   mixed_fourth_by_dual        out_k = sum_ijl f_kijl(x) a_i b_j c_l, one pass of FourthDerivativeDual<K> with the
//                               three outer slots seeded with a, b and c: 8 (K+1) doubles per number
// The mixed passes also give, on request, the lower derivatives they compute alongside and take a seed of their
// second-order slots (MixedPassExtras, below): hvp_H forms its sums of third and fourth derivatives that way.
// Each returns f(x) (the value computed alongside). The adapter's gradients drop it, so that once inlined the work
// only the value needs is dead code (dual.hpp's derivative rules carry the domains); the other passes give it to
// poison_if_not_finite.
//
// For a model whose gradient g is written as a template over the number type (model_adapter.hpp), the
// derivatives of g need no capacity K, and their storage is a per-thread buffer of n numbers that grows once:
//   hessian_vector_by_gradient      out = H(x) v, one pass of g on Dual<double, 1> seeded with v: a few gradients'
//                                   cost
//   hessian_by_gradient             the n x n Hessian, row-major: n such passes (column j along e_j)
//   directional_third_by_gradient   out_k = sum_ij f_kij u_i u_j, one pass of g on Dual<Dual<double, 1>, 1> with
//                                   both slots seeded with u
//   mixed_third_by_gradient         out_k = sum_ij f_kij a_i b_j, the same pass with the slots seeded with a and b
//   mixed_fourth_by_gradient        out_k = sum_ijl f_kijl a_i b_j c_l, one pass of g on
//                                   Dual<Dual<Dual<double, 1>, 1>, 1> seeded with a, b and c: O(n) for a sparse g
//                                   (both mixed passes with MixedPassExtras as above)
// These return nothing (g gives no value); the callers poison their results by the value of f where they need to.
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "nonsep/sdk/dual.hpp"

namespace nonsep::sdk {

// The coordinates a model's T or V receives: the n components of one state.
template <class S>
using Vector = std::span<const S>;

// The scalar types a model's T and V are instantiated with.
template <std::size_t K>
using GradientDual = Dual<double, K>;
template <std::size_t K>
using HessianDual = Dual<Dual<double, K>, 1>;
template <std::size_t K>
using ThirdDerivativeDual = Dual<Dual<Dual<double, K>, 1>, 1>;
template <std::size_t K>
using FourthDerivativeDual = Dual<ThirdDerivativeDual<K>, 1>;

namespace detail {

// Automatic derivatives of a function that is not finite at x are meaningless (log(-1) has the "derivative" -1):
// when the value computed alongside them is not finite, the `size` derivatives in `out` become NaN.
// Written as a select, not a branch, so that the batch loops around it still vectorize.
inline void poison_if_not_finite(double value, double* out, std::size_t size) {
  const bool finite = std::isfinite(value);
  for (std::size_t i = 0; i < size; ++i) out[i] = finite ? out[i] : std::numeric_limits<double>::quiet_NaN();
}

// What a mixed pass (mixed_third_*, mixed_fourth_*) takes and gives beyond its main result, so that hvp_H
// (model_adapter.hpp) gets several derivatives from one pass; a null pointer is a zero seed or a result not wanted.
//   seed      s in the second-order slots: e1 e2 of a third-derivative pass, which adds f'' s to its result; e1 e3
//             and e2 e3 of a fourth, which adds f'''[a, s] + f'''[b, s]
//   along_a   f'' a (either pass);  along_b   f'' b (a third-derivative pass)
//   lower     f'''[b, c] + f'' s (a fourth-derivative pass: its e2 e3 part)
struct MixedPassExtras {
  const double* seed = nullptr;
  double* along_a = nullptr;
  double* along_b = nullptr;
  double* lower = nullptr;
};

template <std::size_t K, class F>
NONSEP_SDK_DUAL_INLINE double gradient_by_dual(const F& f, const double* x, std::size_t n, double* out) {
  using D = GradientDual<K>;
  std::array<D, K> xs;
  for (std::size_t i = 0; i < n; ++i) xs[i] = D::variable(x[i], i);
  const D y = f(Vector<D>(xs.data(), n));
  for (std::size_t i = 0; i < n; ++i) out[i] = y.derivative[i];
  return y.value;
}

template <std::size_t K, class F>
double hessian_by_dual(const F& f, const double* x, std::size_t n, double* out) {
  using Inner = Dual<double, K>;
  using D = HessianDual<K>;
  std::array<D, K> xs;
  for (std::size_t i = 0; i < n; ++i) xs[i].value = Inner::variable(x[i], i);
  double value = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < n; ++i) xs[i].derivative[0] = Inner(i == j ? 1.0 : 0.0);
    const D y = f(Vector<D>(xs.data(), n));
    for (std::size_t i = 0; i < n; ++i) out[i * n + j] = y.derivative[0].derivative[i];
    value = y.value.value;
  }
  return value;
}

template <std::size_t K, class F>
NONSEP_SDK_DUAL_INLINE double mixed_third_by_dual(const F& f, const double* x, const double* a, const double* b,
                                                  std::size_t n, double* out, const MixedPassExtras& extras = {}) {
  using Inner = Dual<double, K>;
  using Middle = Dual<Inner, 1>;
  using D = ThirdDerivativeDual<K>;
  std::array<D, K> xs;
  for (std::size_t i = 0; i < n; ++i) {
    xs[i].value.value = Inner::variable(x[i], i);
    xs[i].value.derivative[0] = Inner(a[i]);
    xs[i].derivative[0] = Middle(b[i]);
    if (extras.seed != nullptr) xs[i].derivative[0].derivative[0] = Inner(extras.seed[i]);  // e1 e2
  }
  const D y = f(Vector<D>(xs.data(), n));
  for (std::size_t k = 0; k < n; ++k) out[k] = y.derivative[0].derivative[0].derivative[k];
  if (extras.along_a != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_a[k] = y.value.derivative[0].derivative[k];
  if (extras.along_b != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_b[k] = y.derivative[0].value.derivative[k];
  return y.value.value.value;
}

template <std::size_t K, class F>
double directional_third_by_dual(const F& f, const double* x, const double* u, std::size_t n, double* out) {
  return mixed_third_by_dual<K>(f, x, u, u, n, out);
}

template <std::size_t K, class F>
NONSEP_SDK_DUAL_INLINE double mixed_fourth_by_dual(const F& f, const double* x, const double* a, const double* b,
                                                   const double* c, std::size_t n, double* out,
                                                   const MixedPassExtras& extras = {}) {
  using Inner = Dual<double, K>;
  using Second = Dual<Inner, 1>;
  using Third = ThirdDerivativeDual<K>;
  using D = FourthDerivativeDual<K>;
  std::array<D, K> xs;
  for (std::size_t i = 0; i < n; ++i) {
    xs[i].value.value.value = Inner::variable(x[i], i);
    xs[i].value.value.derivative[0] = Inner(a[i]);
    xs[i].value.derivative[0] = Second(b[i]);
    xs[i].derivative[0] = Third(c[i]);
    if (extras.seed != nullptr) {
      xs[i].derivative[0].value.derivative[0] = Inner(extras.seed[i]);  // e1 e3
      xs[i].derivative[0].derivative[0].value = Inner(extras.seed[i]);  // e2 e3
    }
  }
  const D y = f(Vector<D>(xs.data(), n));
  for (std::size_t k = 0; k < n; ++k) out[k] = y.derivative[0].derivative[0].derivative[0].derivative[k];
  if (extras.along_a != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_a[k] = y.value.value.derivative[0].derivative[k];
  if (extras.lower != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.lower[k] = y.derivative[0].derivative[0].value.derivative[k];
  return y.value.value.value.value;
}

template <std::size_t K, class F>
NONSEP_SDK_DUAL_INLINE double hessian_vector_by_dual(const F& f, const double* x, const double* v, std::size_t n,
                                                     double* out, double* gradient = nullptr) {
  using Inner = Dual<double, K>;
  using D = HessianDual<K>;
  std::array<D, K> xs;
  for (std::size_t i = 0; i < n; ++i) {
    xs[i].value = Inner::variable(x[i], i);
    xs[i].derivative[0] = Inner(v[i]);
  }
  const D y = f(Vector<D>(xs.data(), n));
  for (std::size_t i = 0; i < n; ++i) out[i] = y.derivative[0].derivative[i];
  if (gradient != nullptr)  // grad f, computed alongside
    for (std::size_t i = 0; i < n; ++i) gradient[i] = y.value.derivative[i];
  return y.value.value;
}

// Two per-thread buffers of n numbers of type D (the point and the gradient), reused by every call on the thread.
template <class D>
struct GradientScratch {
  std::vector<D> x, g;
  static GradientScratch& of_size(std::size_t n) {
    thread_local GradientScratch scratch;
    if (scratch.x.size() < n) {
      scratch.x.resize(n);
      scratch.g.resize(n);
    }
    return scratch;
  }
};

template <class G>
NONSEP_SDK_DUAL_INLINE void hessian_vector_by_gradient(const G& gradient, const double* x, const double* v,
                                                       std::size_t n, double* out) {
  using D = Dual<double, 1>;
  auto& scratch = GradientScratch<D>::of_size(n);
  for (std::size_t i = 0; i < n; ++i) scratch.x[i] = D(x[i], {v[i]});
  gradient(Vector<D>(scratch.x.data(), n), std::span<D>(scratch.g.data(), n));
  for (std::size_t i = 0; i < n; ++i) out[i] = scratch.g[i].derivative[0];
}

template <class G>
void hessian_by_gradient(const G& gradient, const double* x, std::size_t n, double* out) {
  using D = Dual<double, 1>;
  auto& scratch = GradientScratch<D>::of_size(n);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < n; ++i) scratch.x[i] = D(x[i], {i == j ? 1.0 : 0.0});
    gradient(Vector<D>(scratch.x.data(), n), std::span<D>(scratch.g.data(), n));
    for (std::size_t i = 0; i < n; ++i) out[i * n + j] = scratch.g[i].derivative[0];
  }
}

template <class G>
NONSEP_SDK_DUAL_INLINE void directional_third_by_gradient(const G& gradient, const double* x, const double* u,
                                                          std::size_t n, double* out) {
  using Inner = Dual<double, 1>;
  using D = Dual<Inner, 1>;
  auto& scratch = GradientScratch<D>::of_size(n);
  for (std::size_t i = 0; i < n; ++i) scratch.x[i] = D(Inner(x[i], {u[i]}), {Inner(u[i])});
  gradient(Vector<D>(scratch.x.data(), n), std::span<D>(scratch.g.data(), n));
  for (std::size_t k = 0; k < n; ++k) out[k] = scratch.g[k].derivative[0].derivative[0];
}

template <class G>
NONSEP_SDK_DUAL_INLINE void mixed_third_by_gradient(const G& gradient, const double* x, const double* a,
                                                    const double* b, std::size_t n, double* out,
                                                    const MixedPassExtras& extras = {}) {
  using Inner = Dual<double, 1>;
  using D = Dual<Inner, 1>;
  auto& scratch = GradientScratch<D>::of_size(n);
  for (std::size_t i = 0; i < n; ++i)  // the e1 e2 slot seeded with s
    scratch.x[i] = D(Inner(x[i], {a[i]}), {Inner(b[i], {extras.seed != nullptr ? extras.seed[i] : 0.0})});
  gradient(Vector<D>(scratch.x.data(), n), std::span<D>(scratch.g.data(), n));
  for (std::size_t k = 0; k < n; ++k) out[k] = scratch.g[k].derivative[0].derivative[0];
  if (extras.along_a != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_a[k] = scratch.g[k].value.derivative[0];
  if (extras.along_b != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_b[k] = scratch.g[k].derivative[0].value;
}

template <class G>
NONSEP_SDK_DUAL_INLINE void mixed_fourth_by_gradient(const G& gradient, const double* x, const double* a,
                                                     const double* b, const double* c, std::size_t n, double* out,
                                                     const MixedPassExtras& extras = {}) {
  using Inner = Dual<double, 1>;
  using Second = Dual<Inner, 1>;
  using D = Dual<Second, 1>;
  auto& scratch = GradientScratch<D>::of_size(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = extras.seed != nullptr ? extras.seed[i] : 0.0;  // the e1 e3 and e2 e3 slots
    scratch.x[i] = D(Second(Inner(x[i], {a[i]}), {Inner(b[i])}), {Second(Inner(c[i], {s}), {Inner(s)})});
  }
  gradient(Vector<D>(scratch.x.data(), n), std::span<D>(scratch.g.data(), n));
  for (std::size_t k = 0; k < n; ++k) out[k] = scratch.g[k].derivative[0].derivative[0].derivative[0];
  if (extras.along_a != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.along_a[k] = scratch.g[k].value.value.derivative[0];
  if (extras.lower != nullptr)
    for (std::size_t k = 0; k < n; ++k) extras.lower[k] = scratch.g[k].derivative[0].derivative[0].value;
}

}  // namespace detail
}  // namespace nonsep::sdk
