#pragma once
// What one run of any integrator (nonsep or peer) from (q0, p0) to t_end reports back to the benchmark.
#include <cstdint>

namespace nonsep::bench {

struct RunResult {
  double q = 0.0, p = 0.0;  // the end point
  // nonsep: gradient evaluations grad_T + grad_V (each is half of Hamilton's equations), for the comparators (tao,
  // gauss) evaluations of grad H (all of Hamilton's equations, from four model calls);
  // peers: evaluations of Hamilton's equations (dH/dp, -dH/dq) together.
  std::uint64_t evaluations = 0;
  std::uint64_t jacobian_evaluations = 0;  // GSL's implicit methods only
  bool succeeded = true;                   // false when the peer gave up (GSL: Newton or error check failed)
};

}  // namespace nonsep::bench
