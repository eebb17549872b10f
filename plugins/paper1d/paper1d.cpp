#include "paper1d.hpp"

NONSEP_EXPORT_MODEL(Paper1D, "paper1d", "1.0.0",
                    "The 1D test model of Chin's paper, eq. (algham): trajectories harmonic near the origin and "
                    "strongly distorted far from it",
                    "T = p + p^3/6, V = q^2/2 + q^4/12; H_TTV = (1 + p^2/2)^2 (1 + q^2), "
                    "H_VVT = (q + q^3/3)^2 p");
