#pragma once
// A particle in the plane with a position-dependent inverse mass that is a Hessian, in an anisotropic potential:
//   H = (1/2) p . M^-1(q) p + U(q),   M^-1(q) = kappa I + 2 Hess V(q),
// the product form T_i V_ij T_j with T = |p|^2/2 and V = |q|^2/4 + lambda |q|^4/24 plus the separable part
// (nonsep/core/schemes/separable_composition.hpp) K = kappa |p|^2/2 and U = (q1^2 + omega^2 q2^2)/2 + mu q1^2 q2^2:
//   2 Hess V = (1 + lambda |q|^2/3) I + (2 lambda/3) q q^T,
//   H = (1/2)(kappa + 1 + lambda |q|^2/3) |p|^2 + (lambda/3)(q . p)^2 + (q1^2 + omega^2 q2^2)/2 + mu q1^2 q2^2.
// Compact energy shells: for lambda, kappa, mu >= 0, M^-1 >= I and H >= |p|^2/2 + min(1, omega^2) |q|^2/2.
// Parameters "lambda" (0.5, [0, 10]), "kappa" (0.5, [0, 10]), "omega" (1.5, [0.01, 100]), "mu" (0.25, [0, 10]).
// Hand-written twin: tests/support/models.hpp, VariableMass2D. Derivatives by automatic differentiation.
#include <nonsep/plugin_sdk.hpp>

class VariableMass2D {
 public:
  static constexpr std::size_t dimension = 2;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "lambda",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.5,
       .minimum = 0.0,
       .maximum = 10.0,
       .description = "position dependence of the inverse mass (the quartic term of V)"},
      {.name = "kappa",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.5,
       .minimum = 0.0,
       .maximum = 10.0,
       .description = "constant part of the inverse mass, K = kappa |p|^2/2"},
      {.name = "omega",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 1.5,
       .minimum = 0.01,
       .maximum = 100.0,
       .description = "frequency of the potential's q2 direction"},
      {.name = "mu",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.25,
       .minimum = 0.0,
       .maximum = 10.0,
       .description = "coupling mu q1^2 q2^2 of the potential"}};

  explicit VariableMass2D(const nonsep::sdk::ParameterValues& values)
      : lambda_(values.number("lambda")),
        kappa_(values.number("kappa")),
        omega_(values.number("omega")),
        mu_(values.number("mu")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return 0.5 * (p[0] * p[0] + p[1] * p[1]);
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S r2 = q[0] * q[0] + q[1] * q[1];
    return r2 / 4.0 + lambda_ * r2 * r2 / 24.0;
  }
  template <class S>
  S K(nonsep::sdk::Vector<S> p) const {
    return 0.5 * kappa_ * (p[0] * p[0] + p[1] * p[1]);
  }
  template <class S>
  S U(nonsep::sdk::Vector<S> q) const {
    const S x2 = q[0] * q[0], y2 = q[1] * q[1];
    return 0.5 * (x2 + omega_ * omega_ * y2) + mu_ * x2 * y2;
  }

 private:
  double lambda_, kappa_, omega_, mu_;
};
