#pragma once
// The Henon-Heiles system written as one Hamiltonian H(q, p) (a model given by H itself, plugin_abi.h version 6):
//   H = (p1^2 + p2^2)/2 + (q1^2 + q2^2)/2 + lambda (q1^2 q2 - q2^3/3).
// Parameter "lambda" (default 1). Separable, so it is also K(p) + U(q) with K = |p|^2/2 and U the potential; the two
// forms give the same numbers to round-off (tests/plugins/test_general_hamiltonian.cpp). At lambda = 1 the energy
// shells H = E < 1/6 are bounded and, above E ~ 0.11, mostly chaotic (Henon and Heiles, Astron. J. 69, 73 (1964)).
// Gradient and Hessian-vector products by automatic differentiation of H.
#include <nonsep/plugin_sdk.hpp>

class HenonHeiles {
 public:
  static constexpr std::size_t dimension = 2;
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "lambda",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 1.0,
                                                           .description = "strength of the cubic coupling"}};

  explicit HenonHeiles(const nonsep::sdk::ParameterValues& values) : lambda_(values.number("lambda")) {}

  template <class S>
  S H(nonsep::sdk::Vector<S> q, nonsep::sdk::Vector<S> p) const {
    return (p[0] * p[0] + p[1] * p[1]) / 2.0 + (q[0] * q[0] + q[1] * q[1]) / 2.0 +
           lambda_ * (q[0] * q[0] * q[1] - nonsep::sdk::cube(q[1]) / 3.0);
  }

 private:
  double lambda_;
};
