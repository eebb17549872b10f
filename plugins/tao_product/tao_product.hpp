#pragma once
// H = (q^2 + 1)(p^2 + 1)/2 written in the product form H_TTV = T'(p)^2 V''(q) of the paper (eq. hprod) with
//   T'(p) = sqrt((1 + p^2)/2),  V''(q) = 1 + q^2,  that is
//   T(p) = (p sqrt(1 + p^2) + asinh p) / (2 sqrt 2),   V(q) = q^2/2 + q^4/12.
// (This H is a standard test of non-separable integrators, e.g. Tao's.) Defined everywhere. Every derivative written
// out: with g = T'(p), T'' = p / (2 g) and T''' = 1 / (4 g^3); V'' = 1 + q^2, V''' = 2q (what Gauss-Legendre's grad H
// needs at every stage point).
#include <cmath>
#include <nonsep/plugin_sdk.hpp>

struct TaoProduct {
  static constexpr std::size_t dimension = 1;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    using std::asinh, std::sqrt;
    return (p[0] * sqrt(1.0 + p[0] * p[0]) + asinh(p[0])) / (2.0 * std::sqrt(2.0));
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S q2 = q[0] * q[0];
    return q2 / 2.0 + q2 * q2 / 12.0;
  }

  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    out[0] = std::sqrt((1.0 + p[0] * p[0]) / 2.0);
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const { out[0] = q[0] * (1.0 + q[0] * q[0] / 3.0); }
  void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const { out[0] = second_T(p[0]); }
  void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const { out[0] = 1.0 + q[0] * q[0]; }
  void hvp_T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    out[0] = second_T(p[0]) * v[0];
  }
  void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    hessian_V(q, out);
    out[0] *= v[0];
  }
  void d3T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    const double g = std::sqrt((1.0 + p[0] * p[0]) / 2.0);
    out[0] = u[0] * u[0] / (4.0 * g * g * g);
  }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = 2.0 * q[0] * u[0] * u[0];
  }

 private:
  static double second_T(double p) { return p / (2.0 * std::sqrt((1.0 + p * p) / 2.0)); }
};
