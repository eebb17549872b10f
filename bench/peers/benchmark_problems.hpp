#pragma once
// The two test problems of the work-precision benchmark, each written once as templated scalar formulas with
// hand-derived derivatives, and served two ways:
//   - to nonsep as the separable pair T(p), V(q) of H_TTV = T'(p) V''(q) T'(p) (BatchedModel below, which models
//     nonsep::ModelWithHessians for n = 1);
//   - to the peers (GSL, Odeint) as Hamilton's equations of the full H(q, p): dq/dt = dH/dp, dp/dt = -dH/dq,
//     simplified by hand the way a user would write them, with the Jacobian the implicit GSL methods need.
// check_derivatives() compares every derivative with central differences; the benchmark calls it at startup.
//
// A problem type P provides, as static templates in Real:
//   T, grad_T, hessian_T (functions of p), V, grad_V, hessian_V (functions of q),
//   H(q, p), dH_dq(q, p), dH_dp(q, p), and jacobian(q, p) -> 2 x 2 row-major d(dq/dt, dp/dt) / d(q, p).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace nonsep::bench {

// V = q^2/2 + q^4/12 and its derivatives (V'' = 1 + q^2): the potential of both problems below.
struct PaperPotential {
  template <class Real>
  static Real V(Real q) {
    return q * q / 2 + q * q * q * q / 12;
  }
  template <class Real>
  static Real grad_V(Real q) {
    return q + q * q * q / 3;
  }
  template <class Real>
  static Real hessian_V(Real q) {
    return 1 + q * q;
  }
  template <class Real>
  static Real third_V(Real q) {
    return 2 * q;
  }
};

// The paper's 1D test (eq. algham): T = p + p^3/6, V = q^2/2 + q^4/12, H = (1 + p^2/2)^2 (1 + q^2).
struct Paper1D : PaperPotential {
  static constexpr const char* name = "paper1d";
  template <class Real>
  static Real T(Real p) {
    return p + p * p * p / 6;
  }
  template <class Real>
  static Real grad_T(Real p) {
    return 1 + p * p / 2;
  }
  template <class Real>
  static Real hessian_T(Real p) {
    return p;
  }
  template <class Real>
  static Real third_T(Real) {
    return 1;
  }

  template <class Real>
  static Real H(Real q, Real p) {
    const Real u = 1 + p * p / 2;
    return u * u * (1 + q * q);
  }
  template <class Real>
  static Real dH_dq(Real q, Real p) {
    const Real u = 1 + p * p / 2;
    return 2 * q * u * u;
  }
  template <class Real>
  static Real dH_dp(Real q, Real p) {
    return 2 * p * (1 + p * p / 2) * (1 + q * q);
  }
  template <class Real>
  static std::array<Real, 4> jacobian(Real q, Real p) {
    const Real u = 1 + p * p / 2;
    return {4 * q * p * u, 2 * (1 + 3 * p * p / 2) * (1 + q * q),  //
            -2 * u * u, -4 * q * p * u};
  }
};

// A product Hamiltonian H = (q^2 + 1)(p^2 + 1)/2 in TTV form: T'(p) = sqrt((1 + p^2)/2), V''(q) = 1 + q^2,
// so H = T'^2 V'' and Hamilton's equations are dq/dt = p (1 + q^2), dp/dt = -q (1 + p^2).
// T = (p sqrt(1 + p^2) + asinh p) / (2 sqrt 2) is needed only to check grad_T.
struct TaoProduct : PaperPotential {
  static constexpr const char* name = "tao_product";
  template <class Real>
  static Real T(Real p) {
    return (p * std::sqrt(1 + p * p) + std::asinh(p)) / (2 * std::sqrt(Real(2)));
  }
  template <class Real>
  static Real grad_T(Real p) {
    return std::sqrt((1 + p * p) / 2);
  }
  template <class Real>
  static Real hessian_T(Real p) {
    return p / (2 * grad_T(p));
  }
  template <class Real>
  static Real third_T(Real p) {
    const Real g = grad_T(p);
    return 1 / (2 * g) - p * p / (4 * g * g * g);
  }

  template <class Real>
  static Real H(Real q, Real p) {
    return (q * q + 1) * (p * p + 1) / 2;
  }
  template <class Real>
  static Real dH_dq(Real q, Real p) {
    return q * (1 + p * p);
  }
  template <class Real>
  static Real dH_dp(Real q, Real p) {
    return p * (1 + q * q);
  }
  template <class Real>
  static std::array<Real, 4> jacobian(Real q, Real p) {
    return {2 * p * q, 1 + q * q,  //
            -(1 + p * p), -2 * p * q};
  }
};

// Problem P as a nonsep::ModelWithThirdDerivatives of dimension 1 (a batch is `count` independent 1D states); the
// third derivatives serve the comparator schemes (grad H).
template <class P>
struct BatchedModel {
  std::size_t dimension() const { return 1; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::grad_T(p[b]);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::grad_V(q[b]);
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::hessian_T(p[b]);
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::hessian_V(q[b]);
  }
  void d3T(std::span<const double> p, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::third_T(p[b]) * u[b] * u[b];
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = P::third_V(q[b]) * u[b] * u[b];
  }
};

// Every derivative of P against a central difference on a grid of points in [-3, 3]^2. Returns one line per
// mismatch (relative to max(1, |value|), tolerance 1e-6); empty when all agree.
template <class P>
std::vector<std::string> check_derivatives() {
  std::vector<std::string> failures;
  auto compare = [&](const std::string& what, double x, double analytic, auto&& f) {
    const double h = 1e-5 * std::max(1.0, std::abs(x));
    const double numeric = (f(x + h) - f(x - h)) / (2 * h);
    if (!(std::abs(analytic - numeric) <= 1e-6 * std::max(1.0, std::abs(analytic))))
      failures.push_back(std::string(P::name) + ": " + what + " = " + std::to_string(analytic) +
                         " but the central difference gives " + std::to_string(numeric));
  };
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      const double q = 0.5 * i + 0.0137, p = 0.5 * j - 0.0219;  // off the symmetric points
      const std::string at = " at (q, p) = (" + std::to_string(q) + ", " + std::to_string(p) + ")";
      compare("grad_T" + at, p, P::grad_T(p), [](double x) { return P::T(x); });
      compare("hessian_T" + at, p, P::hessian_T(p), [](double x) { return P::grad_T(x); });
      compare("grad_V" + at, q, P::grad_V(q), [](double x) { return P::V(x); });
      compare("hessian_V" + at, q, P::hessian_V(q), [](double x) { return P::grad_V(x); });
      compare("third_T" + at, p, P::third_T(p), [](double x) { return P::hessian_T(x); });
      compare("third_V" + at, q, P::third_V(q), [](double x) { return P::hessian_V(x); });
      const double ttv = P::grad_T(p) * P::hessian_V(q) * P::grad_T(p);
      if (!(std::abs(P::H(q, p) - ttv) <= 1e-13 * std::abs(ttv)))
        failures.push_back(std::string(P::name) + ": H" + at + " = " + std::to_string(P::H(q, p)) +
                           " differs from T' V'' T' = " + std::to_string(ttv));
      compare("dH/dq" + at, q, P::dH_dq(q, p), [&](double x) { return P::H(x, p); });
      compare("dH/dp" + at, p, P::dH_dp(q, p), [&](double x) { return P::H(q, x); });
      const auto J = P::jacobian(q, p);
      compare("d(dq/dt)/dq" + at, q, J[0], [&](double x) { return P::dH_dp(x, p); });
      compare("d(dq/dt)/dp" + at, p, J[1], [&](double x) { return P::dH_dp(q, x); });
      compare("d(dp/dt)/dq" + at, q, J[2], [&](double x) { return -P::dH_dq(x, p); });
      compare("d(dp/dt)/dp" + at, p, J[3], [&](double x) { return -P::dH_dq(q, x); });
    }
  }
  return failures;
}

}  // namespace nonsep::bench
