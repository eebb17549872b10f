#include "henon_heiles.hpp"

NONSEP_EXPORT_HAMILTONIAN(HenonHeiles, "henon_heiles", "1.0.0",
                          "The Henon-Heiles system given by its Hamiltonian H(q, p): bounded and chaotic below the "
                          "escape energy 1/6 (at lambda = 1); for gauss, implicit_midpoint and tao",
                          "H = (p1^2 + p2^2)/2 + (q1^2 + q2^2)/2 + lambda (q1^2 q2 - q2^3/3)");
