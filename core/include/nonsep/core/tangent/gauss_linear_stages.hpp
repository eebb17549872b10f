#pragma once
// The linear stages of Gauss-Legendre's tangent map (tangent_gauss_legendre.hpp) solved directly, a few states at once.
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

// The states solved together (their operations interleaved, eight or four at a time; each state's numbers are those
// of solving it alone, bit for bit).
inline constexpr std::size_t linear_stage_lanes = 8;

// jacobians: s matrices J_i of d x d per state, column-major, J_i's column e of state b at
// jacobians[((b*s + i)*d + e)*d]. vectors: k vectors of d numbers (dq then dp) per state, vector v of state b at
// (b*k + v)*d, dz on entry and dz' on return. Returns a mask of the states whose dz' has a number that is not finite
// (bit b for state b: a Jacobian that is not, or a singular system); their vectors are then unspecified. No states:
// nothing, 0. Throws InvalidArgument unless d is even, 2ns <= 32, k <= 32 and states <= linear_stage_lanes (the sizes
// TangentGaussLegendre solves directly), or when the spans are too short; allocates nothing.
unsigned map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                              std::size_t d, std::span<double> vectors, std::size_t k, std::size_t states);
// One state: true when its dz' is finite.
bool map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                          std::size_t d, std::span<double> vectors, std::size_t k);

}  // namespace nonsep
