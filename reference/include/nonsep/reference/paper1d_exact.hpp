#pragma once
// Exact quantities of the paper's 1D test H = (1 + p^2/2)^2 (1 + q^2) (eq. h1d), from its conserved energy.
// Starting at (q0 > 0, p0 = 0) the orbit turns clockwise: p falls first, q reaches 0 after a quarter period,
// where (1 + p^2/2)^2 = E = 1 + q0^2. The quarter period is the integral of dq / |dq/dt| from 0 to q0, with
// |dq/dt| = |dH/dp| = 2 |p| u (1 + q^2), u = 1 + p^2/2 = sqrt(E / (1 + q^2)). The integrand has an inverse
// square-root singularity at q0, which tanh-sinh quadrature handles; u - 1 is written without cancellation,
// u - 1 = (q0 - q)(q0 + q) / (sqrt(1 + q^2) (sqrt(E) + sqrt(1 + q^2))), using the distance to the endpoint.
#include <algorithm>
#include <boost/math/quadrature/tanh_sinh.hpp>
#include <cmath>

namespace nonsep::reference {

struct Paper1DQuarter {
  double energy;   // H at the start, 1 + q0^2
  double period;   // time to reach q = 0 (a quarter of the full period, by the symmetries q -> -q, p -> -p)
  double p_final;  // p there (negative)
};

inline Paper1DQuarter paper1d_quarter(double q0) {
  const double energy = 1.0 + q0 * q0;
  const double sqrt_e = std::sqrt(energy);
  // tanh_sinh passes xc = a - q on the left half of [a, b] = [0, q0] and xc = b - q on the right half, where it
  // is the exact distance to the singular endpoint.
  auto integrand = [&](double q, double xc) {
    const double distance_to_q0 = q > 0.5 * q0 ? xc : q0 - q;
    const double r = std::sqrt(1.0 + q * q);
    const double u_minus_1 = distance_to_q0 * (q0 + q) / (r * (sqrt_e + r));
    const double u = 1.0 + u_minus_1;
    const double p = std::sqrt(2.0 * u_minus_1);
    return 1.0 / (2.0 * p * u * (1.0 + q * q));
  };
  boost::math::quadrature::tanh_sinh<double> integrator;
  const double period = integrator.integrate(integrand, 0.0, q0, 1e-15);
  return {energy, period, -std::sqrt(2.0 * (sqrt_e - 1.0))};
}

// The exact level curve H(q, p) = 1 + q0^2 through (q0, 0): p as a function of q for |q| <= q0, upper branch
// (the lower one is its negative).
inline double paper1d_level_curve_p(double q0, double q) {
  const double u = std::sqrt((1.0 + q0 * q0) / (1.0 + q * q));
  return std::sqrt(std::max(0.0, 2.0 * (u - 1.0)));
}

}  // namespace nonsep::reference
