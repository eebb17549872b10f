#pragma once
// A two-dimensional analogue of the paper's model (eq. algham) with compact energy shells and a chaotic part of
// phase space, for the dynamics diagnostics (Lyapunov exponents, MEGNO, sections):
//   T(p) = p1 + p2 + (p1^3 + p2^3)/6,    V(q) = |q|^2/2 + |q|^4/12 + coupling q1^2 q2^2,
// so grad T = (1 + p1^2/2, 1 + p2^2/2) and
//   Hess V = (1 + |q|^2/3) I + (2/3) q q^T + coupling [[2 q2^2, 4 q1 q2], [4 q1 q2, 2 q1^2]],
//   H_TTV  = grad T(p) . Hess V(q) grad T(p).
// Parameter "coupling" (default 0.2, range [-0.1, 0.3]).
//
// Compact energy shells. The coupling matrix [[2 b^2, 4 a b], [4 a b, 2 a^2]] (a = q1, b = q2) has eigenvalues
// (a^2 + b^2) +- sqrt((a^2 + b^2)^2 + 12 a^2 b^2), which lie in [-|q|^2, 3 |q|^2] because 12 a^2 b^2 <= 3 |q|^4;
// and (2/3) q q^T is positive semi-definite. Hence Hess V >= (1 + c |q|^2) I with c = 1/3 - max(coupling,
// -3 coupling) > 0 on the allowed range (c >= 1/30). Each component of grad T is at least 1, and
// |grad T|^2 = 2 + |p|^2 + (p1^4 + p2^4)/4 >= 2 + |p|^2. So
//   H_TTV >= (1 + c |q|^2)(2 + |p|^2) >= 2 + 2 c |q|^2 + |p|^2:
// every shell H = E is bounded (|q|^2 <= (E - 2)/(2c), |p|^2 <= E - 2) and H >= 2 everywhere.
//
// Not integrable. At coupling 0.2, MEGNO and the largest Lyapunov exponent find regular orbits (<Y> -> 2,
// exponent decaying like log(t)/t) next to chaotic ones (<Y> growing like lambda t/2, lambda ~ 0.2) at the same
// energy, e.g. q = (0.25, 0.3), p = (-1.5, 0.2) (regular, H = 6.75) and q = (-0.75, 0.3), p = (-1.5, 0.2)
// (chaotic, H = 7.49); tests/core/test_chaos_against_reference.cpp checks both against an independent reference.
// Defined everywhere. Analytic gradients, Hessians, Hessian-vector products and directional third derivatives
// (the tangent maps of the Lyapunov and MEGNO diagnostics evaluate the Hessians 8 times per basic step, and
// Gauss-Legendre's grad H the products and the third derivatives of V at every stage point; automatic
// differentiation checks them in tests/plugins). With u^T Hess V u = (1 + |q|^2/3)|u|^2 + (2/3)(q.u)^2 +
// coupling (2 q2^2 u1^2 + 8 q1 q2 u1 u2 + 2 q1^2 u2^2), d3V's entries are its derivatives in q1 and q2; T''' is 1 on
// the diagonal. The mixed third and the fourth derivatives of hvp_H (Gauss-Legendre's tangent map) are written out too.
#include <nonsep/plugin_sdk.hpp>

class Paper2D {
 public:
  static constexpr std::size_t dimension = 2;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "coupling",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.2,
       .minimum = -0.1,
       .maximum = 0.3,
       .description = "strength of the q1^2 q2^2 term of V; the range keeps Hess V positive definite and the "
                      "energy shells compact"}};

  explicit Paper2D(const nonsep::sdk::ParameterValues& values) : coupling_(values.number("coupling")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] + p[1] + (nonsep::sdk::cube(p[0]) + nonsep::sdk::cube(p[1])) / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S x2 = q[0] * q[0], y2 = q[1] * q[1], r2 = x2 + y2;
    return r2 / 2.0 + r2 * r2 / 12.0 + coupling_ * x2 * y2;
  }

  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    out[0] = 1.0 + 0.5 * p[0] * p[0];
    out[1] = 1.0 + 0.5 * p[1] * p[1];
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    const double x = q[0], y = q[1], radial = 1.0 + (x * x + y * y) / 3.0;
    out[0] = x * radial + 2.0 * coupling_ * x * y * y;
    out[1] = y * radial + 2.0 * coupling_ * x * x * y;
  }

  void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    out[0] = p[0];
    out[1] = out[2] = 0.0;
    out[3] = p[1];
  }
  void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    const double x = q[0], y = q[1], radial = 1.0 + (x * x + y * y) / 3.0;
    out[0] = radial + 2.0 / 3.0 * x * x + 2.0 * coupling_ * y * y;
    out[1] = out[2] = (2.0 / 3.0 + 4.0 * coupling_) * x * y;
    out[3] = radial + 2.0 / 3.0 * y * y + 2.0 * coupling_ * x * x;
  }
  void hvp_T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    out[0] = p[0] * v[0];  // Hess T is diagonal (p1, p2)
    out[1] = p[1] * v[1];
  }
  void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    double h[4];
    hessian_V(q, h);
    out[0] = h[0] * v[0] + h[1] * v[1];
    out[1] = h[2] * v[0] + h[3] * v[1];
  }
  void d3T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = u[0] * u[0];
    out[1] = u[1] * u[1];
  }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    const double x = q[0], y = q[1], a = u[0], b = u[1], u2 = a * a + b * b, qu = x * a + y * b;
    out[0] = 2.0 / 3.0 * x * u2 + 4.0 / 3.0 * qu * a + coupling_ * (8.0 * y * a * b + 4.0 * x * b * b);
    out[1] = 2.0 / 3.0 * y * u2 + 4.0 / 3.0 * qu * b + coupling_ * (4.0 * y * a * a + 8.0 * x * a * b);
  }
  // The mixed third derivatives (the gradient in q of a^T Hess V b; T''' is 1 on the diagonal) and the fourth (of
  // c . d3V(q, a, b): constant, V being quartic) of the Hessian-vector product of H, which Gauss-Legendre's tangent
  // map takes 2n times per stage point.
  void d3T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           std::span<double> out) const {
    out[0] = a[0] * b[0];
    out[1] = a[1] * b[1];
  }
  void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           std::span<double> out) const {
    const double x = q[0], y = q[1], ab = a[0] * b[0] + a[1] * b[1], qa = x * a[0] + y * a[1];
    const double qb = x * b[0] + y * b[1], cross = a[0] * b[1] + a[1] * b[0];
    out[0] = 2.0 / 3.0 * (x * ab + a[0] * qb + b[0] * qa) + 4.0 * coupling_ * (y * cross + x * a[1] * b[1]);
    out[1] = 2.0 / 3.0 * (y * ab + a[1] * qb + b[1] * qa) + 4.0 * coupling_ * (y * a[0] * b[0] + x * cross);
  }
  void d4T(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double>,
           nonsep::sdk::Vector<double>, std::span<double> out) const {
    out[0] = out[1] = 0.0;
  }
  void d4V(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> a, nonsep::sdk::Vector<double> b,
           nonsep::sdk::Vector<double> c, std::span<double> out) const {
    const double ab = a[0] * b[0] + a[1] * b[1], ac = a[0] * c[0] + a[1] * c[1], bc = b[0] * c[0] + b[1] * c[1];
    const double cross = a[0] * b[1] + a[1] * b[0];
    out[0] = 2.0 / 3.0 * (c[0] * ab + ac * b[0] + bc * a[0]) + 4.0 * coupling_ * (c[0] * a[1] * b[1] + c[1] * cross);
    out[1] = 2.0 / 3.0 * (c[1] * ab + ac * b[1] + bc * a[1]) + 4.0 * coupling_ * (c[0] * cross + c[1] * a[0] * b[0]);
  }

 private:
  double coupling_;
};
