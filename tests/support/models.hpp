#pragma once
// Models compiled into the tests, with hand-written derivatives. They are checked against finite differences in
// test_models.cpp before anything relies on them.
#include <cmath>
#include <cstddef>
#include <span>

namespace nonsep::testing {

// The paper's 1D model (eq. algham): T = p + p^3/6, V = q^2/2 + q^4/12, so H_TTV = (1 + p^2/2)^2 (1 + q^2)
// and H_VVT = (q + q^3/3)^2 p.
struct Paper1D {
  std::size_t dimension() const { return 1; }
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
  static double H_TTV(double q, double p) { return std::pow(1.0 + 0.5 * p * p, 2) * (1.0 + q * q); }
  static double H_VVT(double q, double p) { return std::pow(q + q * q * q / 3.0, 2) * p; }
};

// A coupled, anharmonic 2D model for the symplecticity and batch tests:
// T = p1 + p2/2 + (p1^2 + p2^2)^2/24 + p1 p2^2/6, V = (q1^2 + q2^2)/2 + q1^2 q2/3 + q2^4/12.
struct Coupled2D {
  std::size_t dimension() const { return 2; }
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
};

}  // namespace nonsep::testing
