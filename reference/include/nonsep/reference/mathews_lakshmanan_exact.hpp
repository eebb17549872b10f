#pragma once
// The exact solution of the Mathews-Lakshmanan oscillator
//   H = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2 / (1 + lambda q^2),
// a position-dependent inverse mass 1 + lambda q^2 with a potential: the product form T_i V_ij T_j with T = p^2/2,
// V = q^2/4 + lambda q^4/24 (V'' = (1 + lambda q^2)/2), plus U(q) = (1/2) alpha^2 q^2 / (1 + lambda q^2).
//
//   q(t) = A sin(omega t + phi),   omega = alpha / sqrt(1 + lambda A^2),   p(t) = q'(t) / (1 + lambda q(t)^2)
//
// for any amplitude A with 1 + lambda A^2 > 0 (every A for lambda >= 0). Derivation: dq/dt = dH/dp =
// (1 + lambda q^2) p, so H = (1/2)(q'^2 + alpha^2 q^2) / (1 + lambda q^2). With q = A sin(theta), theta = omega t +
// phi, the numerator is A^2 (omega^2 cos^2 + alpha^2 sin^2) = A^2 omega^2 (1 + lambda A^2 sin^2) exactly when alpha^2 -
// omega^2 = omega^2 lambda A^2, which is the omega above; H is then the constant E = A^2 omega^2 / 2, and a motion of
// one degree of freedom on its energy curve with the right velocity is the solution. Period 2 pi / omega.
#include <cmath>

namespace nonsep::reference {

struct MathewsLakshmananState {
  double q, p;
};

struct MathewsLakshmanan {
  double lambda = 0.5;
  double alpha = 1.0;

  double frequency(double amplitude) const { return alpha / std::sqrt(1.0 + lambda * amplitude * amplitude); }
  double period(double amplitude) const { return 2.0 * std::acos(-1.0) / frequency(amplitude); }
  double energy(double amplitude) const {
    const double omega = frequency(amplitude);
    return 0.5 * amplitude * amplitude * omega * omega;
  }
  // The state at time t of the orbit q = A sin(omega t + phi).
  MathewsLakshmananState at(double amplitude, double phase, double t) const {
    const double omega = frequency(amplitude), theta = omega * t + phase;
    const double q = amplitude * std::sin(theta);
    return {q, amplitude * omega * std::cos(theta) / (1.0 + lambda * q * q)};
  }
  double hamiltonian(double q, double p) const {
    const double m = 1.0 + lambda * q * q;
    return 0.5 * m * p * p + 0.5 * alpha * alpha * q * q / m;
  }
};

}  // namespace nonsep::reference
