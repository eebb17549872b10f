#include "variable_mass2d.hpp"

NONSEP_EXPORT_MODEL(VariableMass2D, "variable_mass2d", "1.0.0",
                    "A 2D position-dependent inverse mass kappa I + 2 Hess V(q) in an anisotropic coupled potential",
                    "T = |p|^2/2, V = |q|^2/4 + lambda |q|^4/24, K = kappa |p|^2/2, U = (q1^2 + omega^2 q2^2)/2 + "
                    "mu q1^2 q2^2; H = (1/2) p.(kappa I + 2 Hess V) p + U");
