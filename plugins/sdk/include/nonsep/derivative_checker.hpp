#pragma once
// A derivative checker for model authors (and `nonsep inspect --check`): compares a model's gradients, Hessians
// and directional third derivatives with finite differences at sample points, the way Ceres' GradientChecker does
// for cost functions.
//
// Input: any batched model in the layout of nonsep/core/base/model.hpp (a plugin's PluginModel, a
// nonsep::sdk::ModelAdapter, a hand-written model) with
//   dimension(), grad_T, grad_V                     always,
//   value_T(x, out, count), value_V(x, out, count)  (one value per state) when options.check_gradients,
//   hessian_T, hessian_V                            when options.check_hessians or check_third_derivatives,
//   d3T(x, u, out, count), d3V(x, u, out, count)    when options.check_third_derivatives,
//   hvp_T(x, v, out, count), hvp_V(x, v, out, count) when options.check_hessian_vector_products.
// A model whose type lacks value_T/value_V, the Hessians, d3T/d3V or hvp_T/hvp_V is checked on what it has (those
// checks are skipped and listed in report.skipped).
//
// Method: 5-point central differences, f'(x) ~ [f(x-2h) - 8 f(x-h) + 8 f(x+h) - f(x+2h)] / (12 h) with
// h = options.step * max(1, |x_i|); truncation error O(h^4), rounding error O(eps/h), about 1e-12 relative for
// smooth models at the default step. Gradients are differenced from the values, Hessians from the gradients,
// and d3T(x, u)_k = sum_ij T_ijk u_i u_j, the derivative of u^T H(x) u along e_k, from the Hessians, with one
// direction u per sample point drawn uniformly from [-1, 1]^n (seeded). Hessian-vector products H(x) v are
// differenced from the gradients along v (another seeded direction), g(x + s v) at s = -2h, -h, h, 2h with
// h = options.step * max(1, max_i |x_i|): 4 gradient evaluations, so products are checked without any Hessian.
// Every stencil of one check is one batched call, so a plugin is crossed once per function and sample point.
//
// A model given by H(q, p) itself: check_hamiltonian_derivatives (below), grad_H and hvp_H the same way.
//
// Output: a DerivativeCheckReport. A comparison fails when |analytic - finite difference| >
// options.tolerance * max(1, |finite difference|). A NaN derivative where the finite difference is NaN too (a
// point outside the model's domain, such as log(q) at q < 0) agrees: it is counted in report.not_a_number, not
// as a mismatch. Evaluation failures of the model propagate (ModelError).
//
// Culprits. A Hessian is differenced from the gradient, so a wrong gradient also makes a right Hessian disagree.
// Where a point's gradient disagrees with the values and its Hessian with the gradient, the Hessian's diagonal is
// also compared with second differences of the values, [-f(x-2h) + 16 f(x-h) - 30 f(x) + 16 f(x+h) - f(x+2h)] /
// (12 h^2), within max(tolerance, 1e-5) (second differences lose more digits): when it agrees, the gradient is
// named as the likely culprit (report.culprits), once per function.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/model.hpp"

namespace nonsep {

struct DerivativeCheckOptions {
  std::size_t random_points = 16;  // sample points drawn uniformly from [-box, box]^n (same draw for p and q)
  double box = 1.5;
  std::uint64_t seed = 12345;
  std::vector<std::vector<double>> points;    // further sample points, each with dimension() numbers
  double step = 1e-3;                         // relative finite-difference step
  double tolerance = 1e-6;                    // allowed error, relative to max(1, |finite difference|)
  bool check_gradients = true;                // grad T, grad V against differences of T, V (needs values)
  bool check_hessians = true;                 // Hessians against differences of the gradients
  bool check_third_derivatives = true;        // d3T, d3V against differences of u^T H u (needs Hessians)
  bool check_hessian_vector_products = true;  // hvp_T, hvp_V against differences of the gradients along v
  bool check_kinetic = true;                  // the T functions, with each sample point as p
  bool check_potential = true;                // the V functions, with each sample point as q
};

struct DerivativeMismatch {
  std::string function;  // "grad_T", "grad_V", "hessian_T", "hessian_V", "d3T", "d3V", "hvp_T", "hvp_V" (or _K, _U)
  std::vector<double> point;  // p for *_T and *_K, q for *_V and *_U
  std::size_t component;      // index into the gradient or third derivative (i) or row-major Hessian (i*n + j)
  double computed;
  double finite_difference;
};

struct DerivativeCheckReport {
  std::size_t comparisons = 0;
  double largest_error = 0.0;    // max |computed - finite difference| / max(1, |finite difference|)
  std::size_t not_a_number = 0;  // comparisons (included in `comparisons`) where both were NaN: agreement
  std::vector<DerivativeMismatch> mismatches;
  std::vector<std::string> skipped;   // checks not made, with the reason
  std::vector<std::string> culprits;  // e.g. "grad_V": a wrong gradient that a Hessian's mismatches come from

  bool passed() const { return mismatches.empty(); }
  // Several lines: counts, the largest error, then up to `shown` mismatches and the skipped checks. Numbers in
  // scientific notation: errors with 4 significant digits, points and values with 7.
  std::string summary(std::size_t shown = 10) const {
    std::string text = std::to_string(comparisons) + " derivative entries compared with finite differences, " +
                       std::to_string(mismatches.size()) + " mismatches; largest relative error " +
                       scientific(largest_error, 3) + "\n";
    if (not_a_number > 0)
      text += "  " + std::to_string(not_a_number) +
              " entries were NaN both computed and differenced (points outside the model's domain): agreement\n";
    for (std::size_t k = 0; k < std::min(shown, mismatches.size()); ++k) {
      const auto& m = mismatches[k];
      std::string point;
      for (double x : m.point) point += (point.empty() ? "" : ", ") + scientific(x, 6);
      const bool kinetic = m.function.back() == 'T' || m.function.back() == 'K';
      const char* at = m.function.back() == 'H' ? "(q, p)" : kinetic ? "p" : "q";
      text += "  " + m.function + "[" + std::to_string(m.component) + "] at " + at + " = (" + point + "): computed " +
              scientific(m.computed, 6) + ", finite difference " + scientific(m.finite_difference, 6) +
              ", relative error " +
              scientific(std::abs(m.computed - m.finite_difference) / std::max(1.0, std::abs(m.finite_difference)), 3) +
              "\n";
    }
    if (mismatches.size() > shown) text += "  ... and " + std::to_string(mismatches.size() - shown) + " more\n";
    for (const auto& gradient : culprits) {
      const std::string kind = gradient.substr(gradient.size() - 1);
      text += "  likely culprit: " + gradient + ", which disagrees with the differences of value_" + kind +
              "; hessian_" + kind + " agrees with the second differences of value_" + kind +
              " and disagrees only with those of the wrong " + gradient + ": fix " + gradient + " first\n";
    }
    for (const auto& s : skipped) text += "  skipped: " + s + "\n";
    return text;
  }

  // "1.234e-07" for digits = 3 (digits after the point); "nan", "inf".
  static std::string scientific(double x, int digits) {
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.*e", digits, x);
    return buffer;
  }
};

namespace detail {

template <class M>
concept ModelWithValues = requires(const M& m, std::span<const double> x, std::span<double> out, std::size_t count) {
  m.value_T(x, out, count);
  m.value_V(x, out, count);
};
template <class M>
concept ModelWithHessianFunctions = requires(const M& m, std::span<const double> x, std::span<double> out,
                                             std::size_t count) {
  m.hessian_T(x, out, count);
  m.hessian_V(x, out, count);
};

template <class M>
concept ModelWithThirdDerivativeFunctions = requires(const M& m, std::span<const double> x, std::span<const double> u,
                                                     std::span<double> out, std::size_t count) {
  m.d3T(x, u, out, count);
  m.d3V(x, u, out, count);
};

template <class M>
concept ModelWithHessianVectorProducts = requires(const M& m, std::span<const double> x, std::span<const double> v,
                                                  std::span<double> out, std::size_t count) {
  m.hvp_T(x, v, out, count);
  m.hvp_V(x, v, out, count);
};

// u^T H u for the row-major n x n matrix at h.
inline double quadratic_form(const double* h, const std::vector<double>& u) {
  const std::size_t n = u.size();
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) sum += u[i] * h[i * n + j] * u[j];
  return sum;
}

// The 4n stencil points x -/+ 2h e_i, x -/+ h e_i, in the order (i, offset -2, -1, +1, +2).
inline std::vector<double> stencil(const std::vector<double>& x, double relative_step, std::vector<double>& steps) {
  const std::size_t n = x.size();
  std::vector<double> points;
  points.reserve(4 * n * n);
  steps.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    steps[i] = relative_step * std::max(1.0, std::abs(x[i]));
    for (double offset : {-2.0, -1.0, 1.0, 2.0}) {
      std::vector<double> shifted = x;
      shifted[i] += offset * steps[i];
      points.insert(points.end(), shifted.begin(), shifted.end());
    }
  }
  return points;
}

inline double five_point(const double* f, std::size_t stride, double h) {
  return (f[0] - 8.0 * f[stride] + 8.0 * f[2 * stride] - f[3 * stride]) / (12.0 * h);
}

// The second derivative from f at x - 2h, x - h, x + h, x + 2h (f[0..3]) and at x (center).
inline double five_point_second(const double* f, double center, double h) {
  return (-f[0] + 16.0 * f[1] - 30.0 * center + 16.0 * f[2] - f[3]) / (12.0 * h * h);
}

inline bool agrees(double computed, double difference, double tolerance) {
  return std::abs(computed - difference) <= tolerance * std::max(1.0, std::abs(difference));
}

inline void compare(DerivativeCheckReport& report, const DerivativeCheckOptions& options, const char* function,
                    const std::vector<double>& point, std::size_t component, double computed, double difference) {
  ++report.comparisons;
  if (std::isnan(computed) && std::isnan(difference)) {
    ++report.not_a_number;
    return;
  }
  const double error = std::abs(computed - difference) / std::max(1.0, std::abs(difference));
  report.largest_error = std::max(report.largest_error, std::isfinite(error) ? error : INFINITY);
  if (!(error <= options.tolerance)) report.mismatches.push_back({function, point, component, computed, difference});
}

}  // namespace detail

template <class M>
DerivativeCheckReport check_derivatives(const M& model, const DerivativeCheckOptions& options = {}) {
  const std::size_t n = model.dimension();
  std::vector<std::vector<double>> points = options.points;
  std::mt19937_64 engine(options.seed);
  std::uniform_real_distribution<double> uniform(-options.box, options.box);
  for (std::size_t k = 0; k < options.random_points; ++k) {
    std::vector<double> x(n);
    for (double& xi : x) xi = uniform(engine);
    points.push_back(std::move(x));
  }

  DerivativeCheckReport report;
  constexpr bool has_values = detail::ModelWithValues<M>;
  constexpr bool has_hessians = detail::ModelWithHessianFunctions<M>;
  if (options.check_gradients && !has_values) report.skipped.push_back("gradients: the model has no value_T/value_V");
  constexpr bool has_third = detail::ModelWithThirdDerivativeFunctions<M>;
  if (options.check_hessians && !has_hessians)
    report.skipped.push_back("Hessians: the model has no hessian_T/hessian_V");
  if (options.check_third_derivatives && !(has_third && has_hessians))
    report.skipped.push_back(has_third ? "third derivatives: differencing them needs hessian_T/hessian_V"
                                       : "third derivatives: the model has no d3T/d3V");
  constexpr bool has_products = detail::ModelWithHessianVectorProducts<M>;
  if (options.check_hessian_vector_products && !has_products)
    report.skipped.push_back("Hessian-vector products: the model has no hvp_T/hvp_V");
  std::mt19937_64 product_engine(options.seed + 2);
  std::vector<double> product_direction(n), product(n), along, along_gradients;
  std::mt19937_64 direction_engine(options.seed + 1);
  std::uniform_real_distribution<double> direction_component(-1.0, 1.0);
  std::vector<double> direction(n), third(n), stencil_hessians, quadratic_forms;

  std::vector<double> steps, gradient(n), hessian(n * n), stencil_values, stencil_gradients;
  const auto name_culprit = [&report](const char* gradient_name) {
    if (std::find(report.culprits.begin(), report.culprits.end(), gradient_name) == report.culprits.end())
      report.culprits.push_back(gradient_name);
  };
  for (const auto& x : points) {
    if (x.size() != n) {
      report.skipped.push_back("a sample point with " + std::to_string(x.size()) + " numbers for dimension " +
                               std::to_string(n));
      continue;
    }
    const std::vector<double> shifted = detail::stencil(x, options.step, steps);
    const std::size_t count = 4 * n;
    for (const bool kinetic : {true, false}) {
      if (kinetic ? !options.check_kinetic : !options.check_potential) continue;
      std::size_t gradient_mismatches = 0;
      if constexpr (has_values) {
        if (options.check_gradients) {
          const std::size_t before = report.mismatches.size();
          stencil_values.resize(count);
          if (kinetic) {
            model.grad_T(x, gradient, 1);
            model.value_T(shifted, stencil_values, count);
          } else {
            model.grad_V(x, gradient, 1);
            model.value_V(shifted, stencil_values, count);
          }
          for (std::size_t i = 0; i < n; ++i)
            detail::compare(report, options, kinetic ? "grad_T" : "grad_V", x, i, gradient[i],
                            detail::five_point(stencil_values.data() + 4 * i, 1, steps[i]));
          gradient_mismatches = report.mismatches.size() - before;
        }
      }
      if constexpr (has_hessians) {
        if (options.check_hessians) {
          stencil_gradients.resize(count * n);
          if (kinetic) {
            model.hessian_T(x, hessian, 1);
            model.grad_T(shifted, stencil_gradients, count);
          } else {
            model.hessian_V(x, hessian, 1);
            model.grad_V(shifted, stencil_gradients, count);
          }
          // Column j of the Hessian is the derivative of the gradient along e_j (stencil block j).
          const std::size_t before = report.mismatches.size();
          for (std::size_t j = 0; j < n; ++j)
            for (std::size_t i = 0; i < n; ++i)
              detail::compare(report, options, kinetic ? "hessian_T" : "hessian_V", x, i * n + j, hessian[i * n + j],
                              detail::five_point(stencil_gradients.data() + 4 * j * n + i, n, steps[j]));
          if constexpr (has_values) {
            if (gradient_mismatches > 0 && report.mismatches.size() > before) {
              double center = 0.0;
              if (kinetic)
                model.value_T(x, std::span<double>(&center, 1), 1);
              else
                model.value_V(x, std::span<double>(&center, 1), 1);
              bool diagonal_agrees = true;
              for (std::size_t i = 0; i < n; ++i)
                diagonal_agrees =
                    diagonal_agrees &&
                    detail::agrees(hessian[i * n + i],
                                   detail::five_point_second(stencil_values.data() + 4 * i, center, steps[i]),
                                   std::max(options.tolerance, 1e-5));
              if (diagonal_agrees) name_culprit(kinetic ? "grad_T" : "grad_V");
            }
          }
        }
      }
      if constexpr (has_third && has_hessians) {
        if (options.check_third_derivatives) {
          for (double& u : direction) u = direction_component(direction_engine);
          stencil_hessians.resize(count * n * n);
          quadratic_forms.resize(count);
          if (kinetic) {
            model.d3T(x, direction, third, 1);
            model.hessian_T(shifted, stencil_hessians, count);
          } else {
            model.d3V(x, direction, third, 1);
            model.hessian_V(shifted, stencil_hessians, count);
          }
          for (std::size_t s = 0; s < count; ++s)
            quadratic_forms[s] = detail::quadratic_form(stencil_hessians.data() + s * n * n, direction);
          for (std::size_t k = 0; k < n; ++k)
            detail::compare(report, options, kinetic ? "d3T" : "d3V", x, k, third[k],
                            detail::five_point(quadratic_forms.data() + 4 * k, 1, steps[k]));
        }
      }
      if constexpr (has_products) {
        if (options.check_hessian_vector_products) {
          for (double& v : product_direction) v = direction_component(product_engine);
          double largest = 1.0;
          for (double xi : x) largest = std::max(largest, std::abs(xi));
          const double h = options.step * largest;
          along.resize(4 * n);
          along_gradients.resize(4 * n);
          for (std::size_t s = 0; s < 4; ++s)
            for (std::size_t i = 0; i < n; ++i)
              along[s * n + i] = x[i] + std::array{-2.0, -1.0, 1.0, 2.0}[s] * h * product_direction[i];
          if (kinetic) {
            model.hvp_T(x, product_direction, product, 1);
            model.grad_T(along, along_gradients, 4);
          } else {
            model.hvp_V(x, product_direction, product, 1);
            model.grad_V(along, along_gradients, 4);
          }
          for (std::size_t i = 0; i < n; ++i)
            detail::compare(report, options, kinetic ? "hvp_T" : "hvp_V", x, i, product[i],
                            detail::five_point(along_gradients.data() + i, n, h));
        }
      }
    }
  }
  return report;
}

namespace detail {
// A model's separable part seen as a product-form model: K in the place of T, U in the place of V, so that
// check_derivatives checks it as it checks T and V.
template <class M>
struct SeparablePartView {
  const M& model;
  std::size_t dimension() const { return model.dimension(); }
  void value_T(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.value_K(x, out, count);
  }
  void value_V(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.value_U(x, out, count);
  }
  void grad_T(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.grad_K(x, out, count);
  }
  void grad_V(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.grad_U(x, out, count);
  }
  void hessian_T(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.hessian_K(x, out, count);
  }
  void hessian_V(std::span<const double> x, std::span<double> out, std::size_t count) const {
    model.hessian_U(x, out, count);
  }
};
}  // namespace detail

// The separable part K(p) + U(q) of a model (nonsep/core/base/model.hpp, ModelWithSeparablePart: value_K, value_U,
// grad_K, grad_U, hessian_K, hessian_U) checked as check_derivatives checks T and V: grad K and grad U against
// differences of K and U, their Hessians against differences of the gradients, only the parts the model has
// (has_K(), has_U()). Mismatches name grad_K, grad_U, hessian_K, hessian_U.
template <class M>
DerivativeCheckReport check_separable_derivatives(const M& model, DerivativeCheckOptions options = {}) {
  options.check_third_derivatives = false;
  options.check_kinetic = options.check_kinetic && model.has_K();
  options.check_potential = options.check_potential && model.has_U();
  DerivativeCheckReport report = check_derivatives(detail::SeparablePartView<M>{model}, options);
  for (auto& mismatch : report.mismatches) mismatch.function.back() = mismatch.function.back() == 'T' ? 'K' : 'U';
  return report;
}

namespace detail {
// A model given by H(q, p) itself (nonsep/core/base/model.hpp, ModelWithGeneralHamiltonian, with hvp_H) seen as a
// function of the phase point z = (q, p) of 2n numbers, in the place of T: value_T is H, grad_T is (dH/dq, dH/dp),
// hvp_T is the Hessian of H times a tangent (dq, dp).
template <class M>
struct PhasePointView {
  const M& model;
  mutable std::vector<double> q, p, a, b, dq, dp;
  std::size_t dimension() const { return 2 * model.dimension(); }
  // Splits `count` phase points z into q and p (and tangents into dq, dp).
  void split(std::span<const double> z, std::vector<double>& first, std::vector<double>& second,
             std::size_t count) const {
    const std::size_t n = model.dimension();
    first.resize(count * n);
    second.resize(count * n);
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t i = 0; i < n; ++i) {
        first[k * n + i] = z[k * 2 * n + i];
        second[k * n + i] = z[k * 2 * n + n + i];
      }
  }
  void join(std::span<double> z, std::size_t count) const {
    const std::size_t n = model.dimension();
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t i = 0; i < n; ++i) {
        z[k * 2 * n + i] = a[k * n + i];
        z[k * 2 * n + n + i] = b[k * n + i];
      }
  }
  void value_T(std::span<const double> z, std::span<double> out, std::size_t count) const {
    split(z, q, p, count);
    model.value_H(q, p, out, count);
  }
  void grad_T(std::span<const double> z, std::span<double> out, std::size_t count) const {
    split(z, q, p, count);
    a.resize(q.size());
    b.resize(q.size());
    model.grad_H(q, p, a, b, count);
    join(out, count);
  }
  void hvp_T(std::span<const double> z, std::span<const double> v, std::span<double> out,
             std::size_t count) const requires requires(const M& m, std::span<const double> x, std::span<double> o) {
    m.hvp_H(HamiltonianForm::TTV, x, x, x, x, o, o, count);
  }
  {
    split(z, q, p, count);
    split(v, dq, dp, count);
    a.resize(q.size());
    b.resize(q.size());
    model.hvp_H(HamiltonianForm::TTV, q, p, dq, dp, a, b, count);
    join(out, count);
  }
  // Never called (check_derivatives is asked for neither the V functions nor Hessians).
  void value_V(std::span<const double>, std::span<double>, std::size_t) const {}
  void grad_V(std::span<const double>, std::span<double>, std::size_t) const {}
  void hvp_V(std::span<const double>, std::span<const double>, std::span<double>, std::size_t) const {}
};
}  // namespace detail

// A model given by H(q, p) itself checked as check_derivatives checks T: grad_H against differences of value_H, and
// hvp_H (where the model has it) against differences of grad_H along a seeded tangent, at sample points z = (q, p):
// the random ones drawn in [-box, box]^(2n), options.points each of 2n numbers (q then p). Mismatches name grad_H
// and hvp_H, with the point z = (q, p) and the component of (dH/dq, dH/dp) (n + i for dH/dp_i).
template <class M>
DerivativeCheckReport check_hamiltonian_derivatives(const M& model, DerivativeCheckOptions options = {}) {
  options.check_hessians = options.check_third_derivatives = false;
  options.check_potential = false;
  options.check_kinetic = true;
  DerivativeCheckReport report = check_derivatives(detail::PhasePointView<M>{model, {}, {}, {}, {}, {}, {}}, options);
  for (auto& mismatch : report.mismatches) mismatch.function.back() = 'H';
  for (auto& skipped : report.skipped)
    if (skipped.rfind("Hessian-vector products", 0) == 0) skipped = "hvp_H: the model has none";
  std::erase_if(report.skipped,
                [](const std::string& s) { return s.rfind("Hessians", 0) == 0 || s.rfind("third", 0) == 0; });
  return report;
}

}  // namespace nonsep
