#include "radial.hpp"

NONSEP_EXPORT_MODEL(Radial, "radial", "1.0.0",
                    "Chin's N-dimensional radial generalization of the 1D model (eq. hnd); undefined at p = 0",
                    "T = |p| + |p|^3/6, V = |q|^2/2 + |q|^4/12; "
                    "H_TTV = (1 + p^2/2)^2 [1 + q^2/3 + (2/3) q^2 (p_hat . q_hat)^2]");
