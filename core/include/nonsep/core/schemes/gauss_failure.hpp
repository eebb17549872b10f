#pragma once
// Why a Gauss-Legendre step failed for one state (GaussLegendre::try_step, gauss_legendre.hpp): the two messages,
// each naming its cause and what to do about it.
#include <cstddef>
#include <string>

namespace nonsep {

// The state's iterate is not finite after `iterations` iterations. start_q, start_p: the step's start (n numbers
// each); stage_q, stage_p: the last iterate's stages Z_i, dH_dq, dH_dp: grad H at the stage points start + Z_i,
// component k of stage i at [i * stride + k]. Names the first stage point where grad H is not finite: a point far
// from the start after the first iteration is the iteration diverging (a smaller dt prevents it), one near it H not
// defined there; without such a point, the stages overflowed.
std::string gauss_not_finite_reason(const double* start_q, const double* start_p, const double* stage_q,
                                    const double* stage_p, const double* dH_dq, const double* dH_dp, std::size_t n,
                                    std::size_t stages, std::size_t stride, int iterations);

// The iteration did not converge in max_iterations; last_change its last relative change.
std::string gauss_no_convergence_reason(int max_iterations, double last_change);

}  // namespace nonsep
