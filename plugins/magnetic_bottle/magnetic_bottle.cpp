#include "magnetic_bottle.hpp"

NONSEP_EXPORT_HAMILTONIAN(MagneticBottle, "magnetic_bottle", "1.0.0",
                          "A charged particle in a magnetic bottle (a uniform field at mirror = 0) with an optional "
                          "isotropic harmonic potential, given by its Hamiltonian H(q, p); conserves H and the "
                          "canonical angular momentum x p_y - y p_x; for gauss, implicit_midpoint and tao",
                          "H = |p - A|^2/2 + omega^2 |q|^2/2, A = (B/2)(1 + mirror z^2)(-y, x, 0)");
