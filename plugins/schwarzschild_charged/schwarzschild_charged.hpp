#pragma once
// A charged particle around a Schwarzschild black hole in an asymptotically uniform magnetic field (Wald's
// solution), given by its Hamiltonian H(q, p) (a model given by H itself, plugin_abi.h version 6): in geometric
// units (G = c = M = 1, so the horizon is at r = 2), coordinates q = (t, r, theta, phi), proper time as the
// evolution parameter and the particle's mass 1,
//   H = (1/2) g^{mu nu} (p_mu - A_mu)(p_nu - A_nu),
//   g^{tt} = -1/f, g^{rr} = f, g^{theta theta} = 1/r^2, g^{phi phi} = 1/(r^2 sin^2 theta),   f = 1 - 2/r,
//   A_phi = (beta/2) r^2 sin^2 theta (the charge times the vector potential; beta = q B / m, the other A_mu zero).
// H = -1/2 on the orbits of a massive particle (the mass shell). t and phi do not appear in H, so p_t = -E (the
// energy) and p_phi = L (the angular momentum) are conserved besides H: the standard test problem of the explicit
// symplectic methods for such orbits (Wu, Wang, Sun, Mei and coauthors), chaotic for some starts at small beta
// (e.g. E = 0.995, L = 4.6, beta = 8.9e-4, r = 11 in the equatorial plane). Defined outside the horizon (r > 2,
// sin theta != 0). Parameter "beta" (default 8.9e-4). Gradient and Hessian-vector products by automatic
// differentiation of H.
#include <nonsep/plugin_sdk.hpp>

class SchwarzschildCharged {
 public:
  static constexpr std::size_t dimension = 4;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "beta",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 8.9e-4,
       .description = "charge times field strength over mass, q B / m, in units of 1/M"}};

  explicit SchwarzschildCharged(const nonsep::sdk::ParameterValues& values) : beta_(values.number("beta")) {}

  template <class S>
  S H(nonsep::sdk::Vector<S> q, nonsep::sdk::Vector<S> p) const {
    using std::sin;
    const S r = q[1], f = 1.0 - 2.0 / r, s = sin(q[2]);
    const S r2s2 = r * r * s * s;
    const S l = p[3] - beta_ / 2.0 * r2s2;  // p_phi - A_phi
    return 0.5 * (-p[0] * p[0] / f + f * p[1] * p[1] + p[2] * p[2] / (r * r) + l * l / r2s2);
  }

 private:
  double beta_;
};
