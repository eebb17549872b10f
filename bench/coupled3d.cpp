// The 3-D coupled model of the benchmark's figure 7 as a plugin (coupled3d.hpp).
#include "coupled3d.hpp"

NONSEP_EXPORT_MODEL(Coupled3D, "coupled3d", "1.0.0", "benchmark model: paper2d's analogue in three dimensions",
                    "T = sum (p_i + p_i^3/6), V = |q|^2/2 + |q|^4/12 + coupling sum_{i<j} q_i^2 q_j^2");
