#pragma once
// The paper's N-dimensional radial generalization of eq. (algham), with p = |p| and q = |q|:
//   T(p) = p + p^3/6,   V(q) = q^2/2 + q^4/12,
// so that (eq. hnd)
//   H_TTV = (1 + p^2/2)^2 [1 + q^2/3 + (2/3) q^2 (p_hat . q_hat)^2].
// Dimension: the integer parameter "dimension" (default 2, 1..16; 16 bounds the stack used by automatic
// differentiation).
//
// At p = 0. grad T = (1 + |p|^2/2) p/|p| has no limit there (its direction is that of p), and H_TTV itself depends
// on the direction p_hat, so a state with p = 0 has no defined motion. grad_T and hessian_T therefore refuse
// p = 0 exactly with an evaluation failure ("... undefined at p = 0 ..."); T(0) = 0 itself is fine. V is smooth
// everywhere (written in |q|^2, never |q|), including q = 0, where grad V = 0 and Hess V = identity.
#include <algorithm>
#include <cmath>
#include <nonsep/plugin_sdk.hpp>
#include <string>

struct Radial {
  static constexpr std::size_t max_dimension = 16;
  static constexpr const char* dimension_parameter = "dimension";
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "dimension",
                                                           .type = nonsep::sdk::ParameterType::integer,
                                                           .default_value = 2,
                                                           .minimum = 1,
                                                           .maximum = 16,
                                                           .description = "number of degrees of freedom N"}};

  template <class S>
  static S squared_norm(nonsep::sdk::Vector<S> x) {
    S sum = 0.0;
    for (const S& xi : x) sum += xi * xi;
    return sum;
  }

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    using std::sqrt;
    const S p_norm = sqrt(squared_norm(p));
    return p_norm + nonsep::sdk::cube(p_norm) / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S q2 = squared_norm(q);
    return q2 / 2.0 + q2 * q2 / 12.0;
  }

  // grad T = (1/p + p/2) p_vector.
  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    const double p_norm = norm(p);
    refuse_zero_momentum(p_norm, "grad T");
    const double factor = 1.0 / p_norm + 0.5 * p_norm;
    for (std::size_t i = 0; i < p.size(); ++i) out[i] = factor * p[i];
  }
  // Hess T_ij = (1/p + p/2) (delta_ij - p_hat_i p_hat_j) + p p_hat_i p_hat_j  (T'/p across, T'' along p_hat;
  // this form avoids the cancellation of 1/p terms, e.g. it is exactly p in one dimension).
  void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    const double p_norm = norm(p);
    refuse_zero_momentum(p_norm, "the Hessian of T");
    const std::size_t n = p.size();
    const double across = 1.0 / p_norm + 0.5 * p_norm;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) {
        const double along = (p[i] / p_norm) * (p[j] / p_norm);
        out[i * n + j] = across * ((i == j ? 1.0 : 0.0) - along) + p_norm * along;
      }
  }
  // grad V = (1 + q^2/3) q_vector.
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    const double factor = 1.0 + squared_norm(q) / 3.0;
    for (std::size_t i = 0; i < q.size(); ++i) out[i] = factor * q[i];
  }
  // Hess V_ij = (1 + q^2/3) delta_ij + (2/3) q_i q_j.
  void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    const std::size_t n = q.size();
    const double diagonal = 1.0 + squared_norm(q) / 3.0;
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) out[i * n + j] = (i == j ? diagonal : 0.0) + 2.0 / 3.0 * q[i] * q[j];
  }

 private:
  // |x| without underflow for tiny components (|x| = 1e-200 stays 1e-200, not 0).
  static double norm(nonsep::sdk::Vector<double> x) {
    double scale = 0.0;
    for (double xi : x) scale = std::max(scale, std::abs(xi));
    if (scale == 0.0) return 0.0;
    double sum = 0.0;
    for (double xi : x) sum += (xi / scale) * (xi / scale);
    return scale * std::sqrt(sum);
  }
  static void refuse_zero_momentum(double p_norm, const char* what) {
    if (p_norm == 0.0)
      throw nonsep::sdk::EvaluationError(std::string(what) +
                                         " is undefined at p = 0: grad T = (1 + |p|^2/2) p/|p| has no limit there and "
                                         "H_TTV depends on the direction of p; start from a state with p != 0");
  }
};
