#pragma once
// Standard kinetic energy with the Henon-Heiles potential (paper, eq. erttv):
//   T(p) = (p1^2 + p2^2)/2,   V(q) = (q1^2 + q2^2)/2 + lambda (q1^2 q2 - q2^3/3),
// so that H_TTV = p_i V_ij(q) p_j = p1^2 + p2^2 + 2 lambda (q2 p1^2 + 2 q1 p1 p2 - q2 p2^2).
// Parameter "lambda" (default 1). Defined everywhere. Analytic gradients; Hessians by automatic differentiation.
//
// Not a test of chaos, nor of long runs. H_TTV is linear in q, so dp/dt = -dH/dq depends on p alone: with
// z = p1 + i p2, dz/dt = -2 i lambda conj(z)^2, and K = p1^3 - 3 p1 p2^2 = Re z^3 is conserved besides H (the
// system is integrable). In polar form z = r e^{i theta}, r^3 cos(3 theta) = K and dtheta/dt = -2 lambda K / r^2:
// an orbit with K != 0 turns towards a direction where cos(3 theta) = 0 and reaches it in finite time, with
// r = |p| -> infinity. And V_ij = delta_ij + 2 lambda [[q2, q1], [q1, -q2]] has eigenvalues 1 +- 2 lambda |q|: it
// is positive definite (H_TTV a positive quadratic form in p) only for |q| < 1/(2 |lambda|). For a chaotic model
// with compact energy shells see plugins/paper2d.
#include <nonsep/plugin_sdk.hpp>

class QuadraticKinetic {
 public:
  static constexpr std::size_t dimension = 2;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "lambda",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 1.0,
       .description = "strength of the cubic Henon-Heiles coupling"}};

  explicit QuadraticKinetic(const nonsep::sdk::ParameterValues& values) : lambda_(values.number("lambda")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return (p[0] * p[0] + p[1] * p[1]) / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return (q[0] * q[0] + q[1] * q[1]) / 2.0 + lambda_ * (q[0] * q[0] * q[1] - nonsep::sdk::cube(q[1]) / 3.0);
  }

  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    out[0] = p[0];
    out[1] = p[1];
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    out[0] = q[0] + 2.0 * lambda_ * q[0] * q[1];
    out[1] = q[1] + lambda_ * (q[0] * q[0] - q[1] * q[1]);
  }

 private:
  double lambda_;
};
