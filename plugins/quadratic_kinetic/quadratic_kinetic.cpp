#include "quadratic_kinetic.hpp"

NONSEP_EXPORT_MODEL(QuadraticKinetic, "quadratic_kinetic", "1.0.0",
                    "Standard kinetic energy with the Henon-Heiles potential; H_TTV = p_i V_ij(q) p_j (eq. erttv). "
                    "Integrable (K = p1^3 - 3 p1 p2^2 is conserved), orbits with K != 0 reach infinite momentum in "
                    "finite time, and V_ij is positive definite only for |q| < 1/(2 |lambda|)",
                    "T = |p|^2/2, V = (q1^2 + q2^2)/2 + lambda (q1^2 q2 - q2^3/3); "
                    "H_TTV = p1^2 + p2^2 + 2 lambda (q2 p1^2 + 2 q1 p1 p2 - q2 p2^2)");
