#pragma once
// The paper's one-dimensional model, eq. (algham): T(p) = p + p^3/6, V(q) = q^2/2 + q^4/12, so that
//   H_TTV = T'(p)^2 V''(q) = (1 + p^2/2)^2 (1 + q^2)     (eq. h1d)    and    H_VVT = V'(q)^2 T''(p) = (q + q^3/3)^2 p.
// Defined everywhere. Every derivative the comparators and the tangent maps use is written out (T''' = 1,
// V''' = 2q, T'''' = 0, V'''' = 2): Gauss-Legendre's grad H needs T', the Hessian-vector products and the third
// derivative of V at every stage point, its tangent map (hvp_H) the mixed third and the fourth derivatives, which
// automatic differentiation (nested duals) made most of their cost; tests/plugins compares each with automatic
// differentiation.
#include <nonsep/plugin_sdk.hpp>

struct Paper1D {
  static constexpr std::size_t dimension = 1;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] + nonsep::sdk::cube(p[0]) / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S q2 = q[0] * q[0];
    return q2 / 2.0 + q2 * q2 / 12.0;
  }

  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const { out[0] = 1.0 + 0.5 * p[0] * p[0]; }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const { out[0] = q[0] * (1.0 + q[0] * q[0] / 3.0); }
  void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const { out[0] = p[0]; }
  void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const { out[0] = 1.0 + q[0] * q[0]; }
  void hvp_T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    hessian_T(p, out);
    out[0] *= v[0];
  }
  void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    hessian_V(q, out);
    out[0] *= v[0];
  }
  void d3T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = u[0] * u[0];
  }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = 2.0 * q[0] * u[0] * u[0];
  }
  // The mixed third and the fourth derivatives (T'''' = 0, V'''' = 2) of the Hessian-vector product of H, which
  // Gauss-Legendre's tangent map takes 2n times per stage point.
  void d3T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           std::span<double> out) const {
    out[0] = a[0] * b[0];
  }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           std::span<double> out) const {
    out[0] = 2.0 * q[0] * a[0] * b[0];
  }
  void d4T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double>,
           nonsep::sdk::Vector<double>, std::span<double> out) const {
    out[0] = 0.0;
  }
  void d4V(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           nonsep::sdk::Vector<double> c, std::span<double> out) const {
    out[0] = 2.0 * a[0] * b[0] * c[0];
  }
};
