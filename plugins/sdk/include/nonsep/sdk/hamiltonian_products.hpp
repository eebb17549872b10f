#pragma once
// The passes of ModelAdapter's hvp_H (model_adapter.hpp), the directional derivative of the product form's grad H,
// and of its grad H's third derivatives with their product (d3T_with_product, d3V_with_product): one class that
// reads the adapter's flags and model, so that the adapter states what a model has and this file how hvp_H is formed
// from it.
//
// H = X_i(x) Y_ij(y) X_j(x) with X = T, x = p and Y = V, y = q in form TTV (VVT the other way round). Per state three
// passes, each over the model's written-out derivatives, its gradient templates or T and V themselves
// (automatic_derivatives.hpp), seeded so that one pass also forms the lower derivatives the formula adds
// (MixedPassExtras): X's gradient with its product (one Hessian-column pass where X is differentiated over X itself),
// Y's mixed fourth derivative (third when the tangent has no y part), X's mixed third derivative.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstring>
#include <span>
#include <vector>

#include "nonsep/sdk/automatic_derivatives.hpp"
#include "nonsep/sdk/dual.hpp"

namespace nonsep::sdk::detail {

// Adapter: a ModelAdapter, whose flags (analytic_*, differentiates_gradients, fourth_by_gradients, capacity) say
// which way each derivative is formed; a ProductPasses holds references to it and its model for one call.
template <class Adapter>
class ProductPasses {
 public:
  explicit ProductPasses(const Adapter& adapter) : adapter_(adapter), model_(adapter.model()) {}

  // hvp_H's product term, ttv saying which form: Y the inner function (V at y = q in TTV), X the outer (T at x = p),
  // each with its tangent and output (out_y = d(dH/dy)); spans of count states in the gradient layout.
  template <bool ttv>
  void hamiltonian_products(const double* ys, const double* xs, const double* dys, const double* dxs, double* out_ys,
                            double* out_xs, std::size_t count) const requires Adapter::has_hamiltonian_hessian {
    const std::size_t n = adapter_.batch_dimension();
    auto& scratch = detail::GradientScratch<double>::of_size(3 * n);
    double* g = scratch.x.data();
    double* dg = g + n;
    double* w = dg + n;
    double* sum = scratch.g.data();
    // g and w depend on the point alone: a state at the point (bit for bit) of the last one that formed them (Gauss's
    // tangent map asks for 2n directions at each stage point in a row) keeps them where the same function would form
    // them again whatever the tangent: g from X's gradient (not X's combined pass), w from Y's written-out product
    // (not a by-product of Y's passes, which costs nothing more). A state's numbers never depend on its neighbours.
    std::size_t formed = count;  // the state whose point g and w are of; count: none
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t at = b * n;
      const double *x = xs + at, *dx = dxs + at, *y = ys + at, *dy = dys + at;
      double *out_x = out_xs + at, *out_y = out_ys + at;
      // out_y = Y''''[g, g, dy] + 2 Y'''[g, dg],  out_x = 2 (X'''[dx, w] + X'' sum),  with g = X', dg = X'' dx,
      // w = Y'' g and sum = Y'''[g, dy] + Y'' dg. A tangent without an x part (dx = 0: dg = 0) takes X'' sum by a
      // product; one without a y part, Y's third derivatives instead of its fourth (the unit directions Gauss's
      // tangent map forms its Jacobians from, tangent_gauss_legendre.hpp, are of these two kinds).
      const bool moves_x = std::any_of(dx, dx + n, [](double v) { return v != 0.0; });
      const bool moves_y = std::any_of(dy, dy + n, [](double v) { return v != 0.0; });
      if (!moves_x && !moves_y) {
        std::fill(out_x, out_x + n, 0.0);
        std::fill(out_y, out_y + n, 0.0);
        continue;
      }
      const bool same_point = formed < count && std::memcmp(x, xs + formed * n, n * sizeof(double)) == 0 &&
                              std::memcmp(y, ys + formed * n, n * sizeof(double)) == 0;
      if (same_point && !combined_gradient_pass<ttv>) {
        if (moves_x)
          product_of<ttv>(x, dx, dg, n);
        else
          std::fill(dg, dg + n, 0.0);
      } else {
        gradient_and_product_of<ttv>(x, moves_x ? dx : nullptr, g, dg, n);
      }
      double* const along = same_point && (ttv ? analytic_mixed_V : analytic_mixed_T) ? nullptr : w;
      formed = same_point ? formed : b;
      if (moves_y) {
        mixed_fourth_of<!ttv>(y, g, g, dy, out_y, n,
                              {.seed = moves_x ? dg : nullptr, .along_a = along, .along_b = nullptr, .lower = sum});
      } else {
        mixed_third_of<!ttv>(y, g, dg, out_y, n, {.seed = nullptr, .along_a = along, .along_b = sum});
        for (std::size_t i = 0; i < n; ++i) out_y[i] *= 2.0;
      }
      if (moves_x)
        mixed_third_of<ttv>(x, dx, w, out_x, n, {.seed = sum});
      else
        product_of<ttv>(x, sum, out_x, n);
      for (std::size_t i = 0; i < n; ++i) out_x[i] *= 2.0;
    }
  }
  // The mixed passes of hvp_H (automatic_derivatives.hpp, with its extras), of the gradient templates where they
  // compile for the pass's numbers, else of T (kinetic) or V; their lower results poisoned with the main one.
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void mixed_third_of(const double* x, const double* a, const double* b, double* out,
                                             std::size_t n, const detail::MixedPassExtras& extras) const {
    if constexpr (kinetic ? analytic_mixed_T : analytic_mixed_V) {
      written_third<kinetic>(x, a, b, out, n);
      if (extras.seed != nullptr) add_product<kinetic>(x, extras.seed, out, n);
      if (extras.along_a != nullptr) product_of<kinetic>(x, a, extras.along_a, n);
      if (extras.along_b != nullptr) product_of<kinetic>(x, b, extras.along_b, n);
    } else if constexpr (differentiates_gradients)
      detail::mixed_third_by_gradient(gradient_template_of<kinetic>(), x, a, b, n, out, extras);
    else
      poison_pass(detail::mixed_third_by_dual<capacity>(function_of<kinetic>(), x, a, b, n, out, extras), out, extras,
                  n);
  }

 private:
  static constexpr std::size_t capacity = Adapter::capacity;
  static constexpr bool analytic_grad_T = Adapter::analytic_grad_T, analytic_grad_V = Adapter::analytic_grad_V;
  static constexpr bool analytic_hvp_T = Adapter::analytic_hvp_T, analytic_hvp_V = Adapter::analytic_hvp_V;
  static constexpr bool analytic_mixed_T = Adapter::analytic_mixed_T, analytic_mixed_V = Adapter::analytic_mixed_V;
  static constexpr bool differentiates_gradients = Adapter::differentiates_gradients;
  static constexpr bool fourth_by_gradients = Adapter::fourth_by_gradients;

  // T (kinetic) or V, for any number type, and its gradient template (where the model has them).
  template <bool kinetic>
  auto function_of() const {
    return [this](auto v) {
      if constexpr (kinetic)
        return model_.T(v);
      else
        return model_.V(v);
    };
  }
  template <bool kinetic>
  auto gradient_template_of() const {
    return [this](auto v, auto g) {
      if constexpr (kinetic)
        model_.grad_T(v, g);
      else
        model_.grad_V(v, g);
    };
  }
  // One state's derivatives of T (kinetic) or V, for hvp_H: the gradient and the Hessian-vector product as grad_T and
  // hvp_T compute them, the mixed third and fourth derivatives by automatic differentiation.
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void gradient_of(const double* x, double* out, std::size_t n) const {
    if constexpr (kinetic)
      adapter_.grad_T(std::span<const double>(x, n), std::span<double>(out, n), 1);
    else
      adapter_.grad_V(std::span<const double>(x, n), std::span<double>(out, n), 1);
  }
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void product_of(const double* x, const double* v, double* out, std::size_t n) const {
    if constexpr (kinetic)
      adapter_.hvp_T(std::span<const double>(x, n), std::span<const double>(v, n), std::span<double>(out, n), 1);
    else
      adapter_.hvp_V(std::span<const double>(x, n), std::span<const double>(v, n), std::span<double>(out, n), 1);
  }
  // Whether X's gradient and product come from one pass (X differentiated over X itself).
  template <bool kinetic>
  static constexpr bool combined_gradient_pass = (kinetic ? !analytic_grad_T && !analytic_hvp_T
                                                          : !analytic_grad_V && !analytic_hvp_V) &&
                                                 !differentiates_gradients;
  // g = grad X at x and, with a direction dx, dg = X'' dx (else 0): one Hessian-column pass, which gives the
  // gradient alongside, where X is differentiated over X itself; else the gradient and the product as computed alone.
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void gradient_and_product_of(const double* x, const double* dx, double* g, double* dg,
                                                      std::size_t n) const {
    if (dx == nullptr) {
      gradient_of<kinetic>(x, g, n);
      std::fill(dg, dg + n, 0.0);
    } else if constexpr (combined_gradient_pass<kinetic>) {
      detail::poison_if_not_finite(detail::hessian_vector_by_dual<capacity>(function_of<kinetic>(), x, dx, n, dg, g),
                                   dg, n);
    } else {
      gradient_of<kinetic>(x, g, n);
      product_of<kinetic>(x, dx, dg, n);
    }
  }
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void mixed_fourth_of(
      const double* x, const double* a, const double* b, const double* c, double* out, std::size_t n,
      const detail::MixedPassExtras& extras) const requires Adapter::has_hamiltonian_hessian {
    if constexpr (kinetic ? analytic_mixed_T : analytic_mixed_V) {
      const Vector<double> at(x, n), along_a(a, n), along_b(b, n), along_c(c, n);
      const std::span<double> result(out, n);
      if constexpr (kinetic)
        model_.d4T(at, along_a, along_b, along_c, result);
      else
        model_.d4V(at, along_a, along_b, along_c, result);
      if (extras.seed != nullptr) {
        add_third<kinetic>(x, a, extras.seed, out, n);
        add_third<kinetic>(x, b, extras.seed, out, n);
      }
      if (extras.along_a != nullptr) product_of<kinetic>(x, a, extras.along_a, n);
      if (extras.lower != nullptr) {
        written_third<kinetic>(x, b, c, extras.lower, n);
        if (extras.seed != nullptr) add_product<kinetic>(x, extras.seed, extras.lower, n);
      }
    } else if constexpr (fourth_by_gradients)
      detail::mixed_fourth_by_gradient(gradient_template_of<kinetic>(), x, a, b, c, n, out, extras);
    else
      poison_pass(detail::mixed_fourth_by_dual<capacity>(function_of<kinetic>(), x, a, b, c, n, out, extras), out,
                  extras, n);
  }
  // The model's written-out mixed third derivative of T (kinetic) or V into out, or added to it; its Hessian-vector
  // product added to out.
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void written_third(const double* x, const double* a, const double* b, double* out,
                                            std::size_t n) const {
    const Vector<double> at(x, n), along_a(a, n), along_b(b, n);
    if constexpr (kinetic)
      model_.d3T(at, along_a, along_b, std::span<double>(out, n));
    else
      model_.d3V(at, along_a, along_b, std::span<double>(out, n));
  }
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void add_third(const double* x, const double* a, const double* b, double* out,
                                        std::size_t n) const {
    with_term(n, [&](double* term) {
      written_third<kinetic>(x, a, b, term, n);
      for (std::size_t i = 0; i < n; ++i) out[i] += term[i];
    });
  }
  template <bool kinetic>
  NONSEP_SDK_DUAL_INLINE void add_product(const double* x, const double* v, double* out, std::size_t n) const {
    with_term(n, [&](double* term) {
      product_of<kinetic>(x, v, term, n);
      for (std::size_t i = 0; i < n; ++i) out[i] += term[i];
    });
  }
  // n numbers for a term: on the stack for a model of at most 64 degrees of freedom, else a per-thread buffer.
  template <class F>
  NONSEP_SDK_DUAL_INLINE static void with_term(std::size_t n, const F& use) {
    if constexpr (capacity > 0 && capacity <= 64) {
      std::array<double, capacity> term;
      use(term.data());
    } else {
      thread_local std::vector<double> term;
      if (term.size() < n) term.resize(n);
      use(term.data());
    }
  }
  static void poison_pass(double value, double* out, const detail::MixedPassExtras& extras, std::size_t n) {
    detail::poison_if_not_finite(value, out, n);
    for (double* lower : {extras.along_a, extras.along_b, extras.lower})
      if (lower != nullptr) detail::poison_if_not_finite(value, lower, n);
  }
  const Adapter& adapter_;
  const typename Adapter::Model& model_;
};

}  // namespace nonsep::sdk::detail
