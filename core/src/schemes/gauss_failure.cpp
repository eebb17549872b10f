// Why a Gauss-Legendre step failed for one state (gauss_failure.hpp).
#include "nonsep/core/schemes/gauss_failure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nonsep {

namespace {

// A stage point farther than this times the size of the step's start (at least 1) from it, after the first
// iteration, is the iteration diverging rather than the orbit.
constexpr double stage_far_from_start = 100.0;

std::string vector_text(const double* start, const double* stage, std::size_t n) {
  std::string text = "(";
  char number[32];
  for (std::size_t k = 0; k < n; ++k) {
    std::snprintf(number, sizeof number, "%.17g", start[k] + (stage ? stage[k] : 0.0));
    text += (k == 0 ? "" : ", ") + std::string(number);
  }
  return text + ")";
}

}  // namespace

std::string gauss_not_finite_reason(const double* start_q, const double* start_p, const double* stage_q,
                                    const double* stage_p, const double* dH_dq, const double* dH_dp, std::size_t n,
                                    std::size_t stages, std::size_t stride, int iterations) {
  for (std::size_t i = 0; i < stages; ++i) {
    const std::size_t at = i * stride;
    bool finite = true;
    double start = 1.0, stage = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      finite = finite && std::isfinite(dH_dq[at + k]) && std::isfinite(dH_dp[at + k]);
      start = std::max({start, std::abs(start_q[k]), std::abs(start_p[k])});
      stage = std::max({stage, std::abs(stage_q[at + k]), std::abs(stage_p[at + k])});
    }
    if (finite) continue;
    const std::string where = "grad H is not finite at stage " + std::to_string(i + 1) + " of iteration " +
                              std::to_string(iterations) + ", q = " + vector_text(start_q, stage_q + at, n) +
                              ", p = " + vector_text(start_p, stage_p + at, n);
    if (iterations > 1 && !(stage <= stage_far_from_start * start))
      return where + ", far from the step's start q = " + vector_text(start_q, nullptr, n) +
             ", p = " + vector_text(start_p, nullptr, n) +
             ": the fixed-point iteration diverged, which a smaller dt prevents; if it does not, H is not defined or "
             "not differentiable there, or the orbit runs off (on a non-compact energy shell it can run off without "
             "bound)";
    return where +
           ": H is not defined or not differentiable there, or the orbit ran off to where it overflows (on a "
           "non-compact energy shell it can run off without bound)";
  }
  return "an iterate is not finite after " + std::to_string(iterations) +
         " iterations: the stages overflowed; a smaller dt makes the iteration contract";
}

std::string gauss_no_convergence_reason(int max_iterations, double last_change) {
  char change[32];
  std::snprintf(change, sizeof change, "%.3g", last_change);
  return "no convergence in " + std::to_string(max_iterations) + " iterations, last relative change " + change +
         ": a smaller dt makes the iteration contract, unless the orbit runs off where grad H grows without bound (a "
         "non-compact energy shell)";
}

}  // namespace nonsep
