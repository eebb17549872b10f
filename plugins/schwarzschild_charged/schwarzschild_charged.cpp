#include "schwarzschild_charged.hpp"

NONSEP_EXPORT_HAMILTONIAN(SchwarzschildCharged, "schwarzschild_charged", "1.0.0",
                          "A charged particle around a Schwarzschild black hole in a uniform magnetic field, given by "
                          "its Hamiltonian in (t, r, theta, phi); conserves H (-1/2 on the mass shell), p_t = -E and "
                          "p_phi = L; for gauss, implicit_midpoint and tao",
                          "H = (1/2) g^{mu nu}(p_mu - A_mu)(p_nu - A_nu), Schwarzschild metric (M = 1), "
                          "A_phi = (beta/2) r^2 sin^2 theta");
