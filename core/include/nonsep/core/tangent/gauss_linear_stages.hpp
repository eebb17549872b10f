#pragma once
// The linear stages of Gauss-Legendre's tangent map (tangent_gauss_legendre.hpp) solved directly, for one state.
// Given J_i = Df(Y_i) at the step's s stage points (d x d, d = 2n, f = (dH/dp, -dH/dq)), the stage equations
//   dZ_i - dt sum_j a_ij J_j dZ_j = dt sum_j a_ij J_j dz        (i = 1..s)
// are one linear system of size sd, eliminated once (Gaussian elimination with partial pivoting) for the state's k
// tangent vectors together; then
//   dz' = dz + dt sum_i b_i J_i (dz + dZ_i).
// This is the exact derivative of the collocation map at the step's stage points (Hairer, Lubich, Wanner,
// Geometric Numerical Integration, VI.4), the limit the fixed-point iteration of tangent_gauss_legendre.hpp
// converges to.
#include <cstddef>
#include <span>

#include "nonsep/core/schemes/gauss_legendre.hpp"

namespace nonsep {

// jacobians: s matrices J_i of d x d, column-major, J_i's column e at jacobians[(i*d + e)*d]. vectors: k vectors
// of d numbers (dq then dp), dz on entry and dz' on return. Returns false when a number of dz' is not finite (a
// Jacobian that is not, or a singular system): vectors are then unspecified. Throws InvalidArgument unless d is even,
// 2ns <= 32 and k <= 32 (the sizes TangentGaussLegendre solves directly); allocates nothing.
bool map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                          std::size_t d, std::span<double> vectors, std::size_t k);

}  // namespace nonsep
