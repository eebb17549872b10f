#include "paper2d.hpp"

NONSEP_EXPORT_MODEL(Paper2D, "paper2d", "1.0.0",
                    "A 2D analogue of the paper's model with compact energy shells (H >= 2 + |p|^2 + 2c|q|^2) and "
                    "both regular and chaotic orbits, for Lyapunov exponents, MEGNO and Poincare sections",
                    "T = p1 + p2 + (p1^3 + p2^3)/6, V = |q|^2/2 + |q|^4/12 + coupling q1^2 q2^2; "
                    "H_TTV = grad T . Hess V grad T with grad T = (1 + p1^2/2, 1 + p2^2/2)");
