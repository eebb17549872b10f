#pragma once
// Models compiled into the tests, with hand-written derivatives. value_T and value_V (T and V themselves, one value
// per state) let the SDK's derivative checker (nonsep/derivative_checker.hpp) compare the gradients and Hessians
// with finite differences in test_models.cpp before anything relies on them.
#include <cmath>
#include <cstddef>
#include <span>

namespace nonsep::testing {

// The paper's 1D model (eq. algham): T = p + p^3/6, V = q^2/2 + q^4/12, so H_TTV = (1 + p^2/2)^2 (1 + q^2)
// and H_VVT = (q + q^3/3)^2 p.
struct Paper1D {
  std::size_t dimension() const { return 1; }
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = p[b] + p[b] * p[b] * p[b] / 6.0;
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = q[b] * q[b] / 2.0 + std::pow(q[b], 4) / 12.0;
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 1.0 + 0.5 * p[b] * p[b];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = q[b] + q[b] * q[b] * q[b] / 3.0;
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = p[b];
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 1.0 + q[b] * q[b];
  }
  // d3T/dp3 = 1, d3V/dq3 = 2q.
  void d3T(std::span<const double>, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = u[b] * u[b];
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 2.0 * q[b] * u[b] * u[b];
  }
  static double H_TTV(double q, double p) { return std::pow(1.0 + 0.5 * p * p, 2) * (1.0 + q * q); }
  // H_TTV for any scalar type (the references differentiate it): x = (q, p).
  template <class S>
  static S hamiltonian(const S* x) {
    const S g = 1.0 + 0.5 * x[1] * x[1];
    return g * g * (1.0 + x[0] * x[0]);
  }
  static double H_VVT(double q, double p) { return std::pow(q + q * q * q / 3.0, 2) * p; }
};

// A coupled, anharmonic 2D model for the symplecticity and batch tests:
// T = p1 + p2/2 + (p1^2 + p2^2)^2/24 + p1 p2^2/6, V = (q1^2 + q2^2)/2 + q1^2 q2/3 + q2^4/12.
struct Coupled2D {
  std::size_t dimension() const { return 2; }
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = p[2 * b], y = p[2 * b + 1], r2 = x * x + y * y;
      out[b] = x + y / 2.0 + r2 * r2 / 24.0 + x * y * y / 6.0;
    }
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      out[b] = (x * x + y * y) / 2.0 + x * x * y / 3.0 + std::pow(y, 4) / 12.0;
    }
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = p[2 * b], y = p[2 * b + 1], r2 = x * x + y * y;
      out[2 * b] = 1.0 + r2 * x / 6.0 + y * y / 6.0;
      out[2 * b + 1] = 0.5 + r2 * y / 6.0 + x * y / 3.0;
    }
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      out[2 * b] = x + 2.0 * x * y / 3.0;
      out[2 * b + 1] = y + x * x / 3.0 + y * y * y / 3.0;
    }
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = p[2 * b], y = p[2 * b + 1], r2 = x * x + y * y;
      double* h = out.data() + 4 * b;
      h[0] = r2 / 6.0 + x * x / 3.0;
      h[1] = h[2] = x * y / 3.0 + y / 3.0;
      h[3] = r2 / 6.0 + y * y / 3.0 + x / 3.0;
    }
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      double* h = out.data() + 4 * b;
      h[0] = 1.0 + 2.0 * y / 3.0;
      h[1] = h[2] = 2.0 * x / 3.0;
      h[3] = 1.0 + y * y;
    }
  }
  // Third derivatives: T_000 = p1, T_001 = p2/3, T_011 = (p1 + 1)/3, T_111 = p2; V_001 = 2/3, V_111 = 2 q2, the
  // others zero. out_k = sum_ij D_ijk u_i u_j.
  void d3T(std::span<const double> p, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = p[2 * b], y = p[2 * b + 1], u0 = u[2 * b], u1 = u[2 * b + 1];
      out[2 * b] = x * u0 * u0 + 2.0 * y / 3.0 * u0 * u1 + (x + 1.0) / 3.0 * u1 * u1;
      out[2 * b + 1] = y / 3.0 * u0 * u0 + 2.0 * (x + 1.0) / 3.0 * u0 * u1 + y * u1 * u1;
    }
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double y = q[2 * b + 1], u0 = u[2 * b], u1 = u[2 * b + 1];
      out[2 * b] = 4.0 / 3.0 * u0 * u1;
      out[2 * b + 1] = 2.0 / 3.0 * u0 * u0 + 2.0 * y * u1 * u1;
    }
  }
};

// The 2D analogue of the paper's model with a coupling, hand-written twin of plugins/paper2d (whose header proves
// the energy shells compact and explains the choice):
//   T = p1 + p2 + (p1^3 + p2^3)/6,   V = |q|^2/2 + |q|^4/12 + coupling q1^2 q2^2.
struct Paper2D {
  double coupling = 0.2;

  std::size_t dimension() const { return 2; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < 2 * count; ++i) out[i] = 1.0 + 0.5 * p[i] * p[i];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1], radial = 1.0 + (x * x + y * y) / 3.0;
      out[2 * b] = x * radial + 2.0 * coupling * x * y * y;
      out[2 * b + 1] = y * radial + 2.0 * coupling * x * x * y;
    }
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      double* h = out.data() + 4 * b;
      h[0] = p[2 * b];
      h[1] = h[2] = 0.0;
      h[3] = p[2 * b + 1];
    }
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) hessian_V_at(q[2 * b], q[2 * b + 1], out.data() + 4 * b);
  }
  template <class S>
  void hessian_V_at(const S& x, const S& y, S* h) const {
    const S radial = 1.0 + (x * x + y * y) / 3.0;
    h[0] = radial + 2.0 / 3.0 * x * x + 2.0 * coupling * y * y;
    h[1] = 2.0 / 3.0 * x * y + 4.0 * coupling * x * y;
    h[2] = h[1];
    h[3] = radial + 2.0 / 3.0 * y * y + 2.0 * coupling * x * x;
  }
  // H_TTV = grad T . Hess V grad T for any scalar type, x = (q1, q2, p1, p2).
  template <class S>
  S hamiltonian(const S* x) const {
    S h[4];
    hessian_V_at(x[0], x[1], h);
    const S g0 = 1.0 + 0.5 * x[2] * x[2], g1 = 1.0 + 0.5 * x[3] * x[3];
    return g0 * (h[0] * g0 + h[1] * g1) + g1 * (h[2] * g0 + h[3] * g1);
  }
};

// The paper's radial model (eq. hnd) in two dimensions, hand-written twin of plugins/radial: T = |p| + |p|^3/6,
// V = |q|^2/2 + |q|^4/12. Integrable (H and the angular momentum q1 p2 - q2 p1 are conserved); undefined at p = 0.
struct Radial2D {
  std::size_t dimension() const { return 2; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double r = std::hypot(p[2 * b], p[2 * b + 1]), factor = 1.0 / r + 0.5 * r;
      out[2 * b] = factor * p[2 * b];
      out[2 * b + 1] = factor * p[2 * b + 1];
    }
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double factor = 1.0 + (q[2 * b] * q[2 * b] + q[2 * b + 1] * q[2 * b + 1]) / 3.0;
      out[2 * b] = factor * q[2 * b];
      out[2 * b + 1] = factor * q[2 * b + 1];
    }
  }
  // (1/p + p/2)(I - p_hat p_hat^T) + p p_hat p_hat^T
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double r = std::hypot(p[2 * b], p[2 * b + 1]), across = 1.0 / r + 0.5 * r;
      const double u[2] = {p[2 * b] / r, p[2 * b + 1] / r};
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) out[4 * b + 2 * i + j] = across * ((i == j) - u[i] * u[j]) + r * u[i] * u[j];
    }
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1], diagonal = 1.0 + (x * x + y * y) / 3.0;
      double* h = out.data() + 4 * b;
      h[0] = diagonal + 2.0 / 3.0 * x * x;
      h[1] = h[2] = 2.0 / 3.0 * x * y;
      h[3] = diagonal + 2.0 / 3.0 * y * y;
    }
  }
  // H_TTV = (1 + p^2/2)^2 [1 + q^2/3 + (2/3)(p_hat . q)^2] for any scalar type, x = (q1, q2, p1, p2).
  template <class S>
  static S hamiltonian(const S* x) {
    using std::sqrt;
    const S p2 = x[2] * x[2] + x[3] * x[3], q2 = x[0] * x[0] + x[1] * x[1], dot = x[0] * x[2] + x[1] * x[3];
    const S g = 1.0 + 0.5 * p2;
    return g * g * (1.0 + q2 / 3.0 + 2.0 / 3.0 * dot * dot / p2);
  }
};

// The Mathews-Lakshmanan oscillator H = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2 / (1 + lambda q^2), hand-written
// twin of plugins/mathews_lakshmanan: T = p^2/2, V = q^2/4 + lambda q^4/24 (T' V'' T' = (1/2)(1 + lambda q^2) p^2),
// the separable U = (1/2) alpha^2 q^2 / (1 + lambda q^2) and no K. Exact solution:
// nonsep/reference/mathews_lakshmanan_exact.hpp.
struct MathewsLakshmanan {
  double lambda = 0.5;
  double alpha = 1.0;

  std::size_t dimension() const { return 1; }
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * p[b] * p[b];
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = q[b] * q[b] / 4.0 + lambda * std::pow(q[b], 4) / 24.0;
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = p[b];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * q[b] + lambda * q[b] * q[b] * q[b] / 6.0;
  }
  void hessian_T(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 1.0;
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * (1.0 + lambda * q[b] * q[b]);
  }
  void d3T(std::span<const double>, std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.0;
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = lambda * q[b] * u[b] * u[b];
  }
  bool has_K() const { return false; }
  bool has_U() const { return true; }
  void value_K(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.0;
  }
  void grad_K(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.0;
  }
  void hessian_K(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.0;
  }
  void value_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * alpha * alpha * q[b] * q[b] / (1.0 + lambda * q[b] * q[b]);
  }
  void grad_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double m = 1.0 + lambda * q[b] * q[b];
      out[b] = alpha * alpha * q[b] / (m * m);
    }
  }
  void hessian_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double m = 1.0 + lambda * q[b] * q[b];
      out[b] = alpha * alpha * (1.0 - 3.0 * lambda * q[b] * q[b]) / (m * m * m);
    }
  }
};

// A 2D position-dependent inverse mass with a potential, hand-written twin of plugins/variable_mass2d:
//   H = p . Hess V(q) p + K + U = (1/2) p . (kappa I + 2 Hess V(q)) p + U(q),   T = |p|^2/2,   V = |q|^2/4 + lambda
//   |q|^4/24, K = kappa |p|^2/2,   U = (q1^2 + omega^2 q2^2)/2 + mu q1^2 q2^2.
// Hess V = (1/2)(1 + lambda |q|^2/3) I + (lambda/3) q q^T is positive definite for lambda >= 0.
struct VariableMass2D {
  double lambda = 0.5, kappa = 0.5, omega = 1.5, mu = 0.25;
  bool with_K = true, with_U = true;

  std::size_t dimension() const { return 2; }
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * (p[2 * b] * p[2 * b] + p[2 * b + 1] * p[2 * b + 1]);
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double r2 = q[2 * b] * q[2 * b] + q[2 * b + 1] * q[2 * b + 1];
      out[b] = r2 / 4.0 + lambda * r2 * r2 / 24.0;
    }
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < 2 * count; ++i) out[i] = p[i];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double r2 = q[2 * b] * q[2 * b] + q[2 * b + 1] * q[2 * b + 1], factor = 0.5 + lambda * r2 / 6.0;
      out[2 * b] = factor * q[2 * b];
      out[2 * b + 1] = factor * q[2 * b + 1];
    }
  }
  void hessian_T(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      double* h = out.data() + 4 * b;
      h[0] = h[3] = 1.0;
      h[1] = h[2] = 0.0;
    }
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1], diagonal = 0.5 + lambda * (x * x + y * y) / 6.0;
      double* h = out.data() + 4 * b;
      h[0] = diagonal + lambda * x * x / 3.0;
      h[1] = h[2] = lambda * x * y / 3.0;
      h[3] = diagonal + lambda * y * y / 3.0;
    }
  }
  // d3T = 0; V_ijk = (lambda/3)(delta_ij q_k + delta_ik q_j + delta_jk q_i), so out_k = (lambda/3)(|u|^2 q_k + 2 (u.q)
  // u_k).
  void d3T(std::span<const double>, std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < 2 * count; ++i) out[i] = 0.0;
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double u0 = u[2 * b], u1 = u[2 * b + 1], uu = u0 * u0 + u1 * u1, uq = u0 * q[2 * b] + u1 * q[2 * b + 1];
      out[2 * b] = lambda / 3.0 * (uu * q[2 * b] + 2.0 * uq * u0);
      out[2 * b + 1] = lambda / 3.0 * (uu * q[2 * b + 1] + 2.0 * uq * u1);
    }
  }
  bool has_K() const { return with_K; }
  bool has_U() const { return with_U; }
  void value_K(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 0.5 * kappa * (p[2 * b] * p[2 * b] + p[2 * b + 1] * p[2 * b + 1]);
  }
  void grad_K(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < 2 * count; ++i) out[i] = kappa * p[i];
  }
  void hessian_K(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      double* h = out.data() + 4 * b;
      h[0] = h[3] = kappa;
      h[1] = h[2] = 0.0;
    }
  }
  void value_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      out[b] = 0.5 * (x * x + omega * omega * y * y) + mu * x * x * y * y;
    }
  }
  void grad_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      out[2 * b] = x + 2.0 * mu * x * y * y;
      out[2 * b + 1] = omega * omega * y + 2.0 * mu * x * x * y;
    }
  }
  void hessian_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      const double x = q[2 * b], y = q[2 * b + 1];
      double* h = out.data() + 4 * b;
      h[0] = 1.0 + 2.0 * mu * y * y;
      h[1] = h[2] = 4.0 * mu * x * y;
      h[3] = omega * omega + 2.0 * mu * x * x;
    }
  }
  // The full H for any scalar type, x = (q1, q2, p1, p2).
  template <class S>
  S hamiltonian(const S* x) const {
    const S r2 = x[0] * x[0] + x[1] * x[1], pp = x[2] * x[2] + x[3] * x[3], qp = x[0] * x[2] + x[1] * x[3];
    S h = (0.5 + lambda * r2 / 6.0) * pp + lambda / 3.0 * qp * qp;
    if (with_K) h = h + 0.5 * kappa * pp;
    if (with_U) h = h + 0.5 * (x[0] * x[0] + omega * omega * x[1] * x[1]) + mu * x[0] * x[0] * x[1] * x[1];
    return h;
  }
};

// VariableMass2D with the roles of T and V swapped, for the VVT form: V = |q|^2/2 and T = |p|^2/4 + lambda |p|^4/24,
// so that H_VVT = V_i T_ij V_j = q . Hess T(p) q, and the same K and U:
//   H = (1/2)(1 + lambda |p|^2/3) |q|^2 + (lambda/3) (q.p)^2 + kappa |p|^2/2 + (q1^2 + omega^2 q2^2)/2 + mu q1^2 q2^2.
struct SwappedVariableMass2D : VariableMass2D {
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    VariableMass2D::value_V(p, out, count);
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    VariableMass2D::value_T(q, out, count);
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    VariableMass2D::grad_V(p, out, count);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    VariableMass2D::grad_T(q, out, count);
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    VariableMass2D::hessian_V(p, out, count);
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    VariableMass2D::hessian_T(q, out, count);
  }
  void d3T(std::span<const double> p, std::span<const double> u, std::span<double> out, std::size_t count) const {
    VariableMass2D::d3V(p, u, out, count);
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    VariableMass2D::d3T(q, u, out, count);
  }
  // The full H for any scalar type, x = (q1, q2, p1, p2).
  template <class S>
  S hamiltonian(const S* x) const {
    const S r2 = x[0] * x[0] + x[1] * x[1], pp = x[2] * x[2] + x[3] * x[3], qp = x[0] * x[2] + x[1] * x[3];
    S h = (0.5 + lambda * pp / 6.0) * r2 + lambda / 3.0 * qp * qp;
    if (with_K) h = h + 0.5 * kappa * pp;
    if (with_U) h = h + 0.5 * (x[0] * x[0] + omega * omega * x[1] * x[1]) + mu * x[0] * x[0] * x[1] * x[1];
    return h;
  }
};

}  // namespace nonsep::testing
