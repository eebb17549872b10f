#include "lattice_chain.hpp"

NONSEP_EXPORT_MODEL(LatticeChain, "lattice_chain", "1.0.0",
                    "a periodic chain of n sites with strain-dependent inverse mass; every evaluation O(n)",
                    "T = sum_i (p_i^2/2 + a p_i^4/12), V = sum_i [q_i^2/2 + k r_i^2/2 + b r_i^4/4], "
                    "r_i = q_(i+1) - q_i (periodic); H_TTV = sum_ij T_i V_ij T_j with V_ij tridiagonal");
