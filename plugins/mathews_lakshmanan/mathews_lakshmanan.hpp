#pragma once
// The Mathews-Lakshmanan oscillator, a position-dependent inverse mass with a potential:
//   H = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2 / (1 + lambda q^2).
// Product form plus a separable part (nonsep/core/schemes/separable_composition.hpp): T = p^2/2 and V = q^2/4 + lambda
// q^4/24 give T'(p)^2 V''(q) = (1/2)(1 + lambda q^2) p^2, and U(q) = (1/2) alpha^2 q^2 / (1 + lambda q^2); no K. Exact
// solution (nonsep/reference/mathews_lakshmanan_exact.hpp): q(t) = A sin(omega t + phi) with omega = alpha / sqrt(1 +
// lambda A^2), p = q' / (1 + lambda q^2), for 1 + lambda A^2 > 0. Parameters "lambda" (default 0.5, range [0, 10]: the
// inverse mass stays >= 1) and "alpha" (default 1, > 0). Defined everywhere for lambda >= 0. Analytic gradients; T's
// and V's Hessians, Hessian-vector products and third derivatives written out (T'' = 1, V'' = (1 + lambda q^2)/2,
// V''' = lambda q: what Gauss-Legendre's grad H needs at every stage point); U's Hessian by automatic
// differentiation.
#include <nonsep/plugin_sdk.hpp>

class MathewsLakshmanan {
 public:
  static constexpr std::size_t dimension = 1;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "lambda",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.5,
       .minimum = 0.0,
       .maximum = 10.0,
       .description = "strength of the position dependence of the inverse mass 1 + lambda q^2"},
      {.name = "alpha",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 1.0,
       .minimum = 1e-3,
       .maximum = 1e3,
       .description = "frequency of the small oscillations"}};

  explicit MathewsLakshmanan(const nonsep::sdk::ParameterValues& values)
      : lambda_(values.number("lambda")), alpha_(values.number("alpha")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return 0.5 * p[0] * p[0];
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S q2 = q[0] * q[0];
    return q2 / 4.0 + lambda_ * q2 * q2 / 24.0;
  }
  template <class S>
  S U(nonsep::sdk::Vector<S> q) const {
    const S q2 = q[0] * q[0];
    return 0.5 * alpha_ * alpha_ * q2 / (1.0 + lambda_ * q2);
  }

  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const { out[0] = p[0]; }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    out[0] = q[0] * (0.5 + lambda_ * q[0] * q[0] / 6.0);
  }
  void hessian_T(nonsep::sdk::Vector<double>, std::span<double> out) const { out[0] = 1.0; }
  void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    out[0] = 0.5 * (1.0 + lambda_ * q[0] * q[0]);
  }
  void hvp_T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> v, std::span<double> out) const { out[0] = v[0]; }
  void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    hessian_V(q, out);
    out[0] *= v[0];
  }
  void d3T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double>, std::span<double> out) const { out[0] = 0.0; }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = lambda_ * q[0] * u[0] * u[0];
  }
  void grad_U(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    const double m = 1.0 + lambda_ * q[0] * q[0];
    out[0] = alpha_ * alpha_ * q[0] / (m * m);
  }

 private:
  double lambda_, alpha_;
};
