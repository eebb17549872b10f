#pragma once
// GSL peers (benchmark only: GSL is GPL and the product never links it): the implicit Gauss-Legendre
// Runge-Kutta methods of gsl_odeiv2, rk2imp (implicit midpoint, order 2) and rk4imp (2-stage Gauss, order 4),
// both symplectic, run at a fixed step through gsl_odeiv2_driver_apply_fixed_step on Hamilton's equations of
// the full H with the hand-derived Jacobian (benchmark_problems.hpp).
//
// How GSL behaves here, which the benchmark has to live with (GSL 2.7, ode-initval2/rk4imp.c, evolve.c):
//   - each step of size h also takes two steps of h/2 for a step-doubling error estimate and returns the
//     result of the two half steps; the stage equations are solved by modified Newton (at most 7 iterations)
//     to the driver's error level epsabs (epsrel = 0 here), which is therefore the Newton tolerance;
//   - apply_fixed_step fails (GSL_FAILURE, y restored) when Newton does not converge or when the step's
//     estimated local error exceeds that level. So every step size is tried at a ladder of tolerances and a
//     failed run is reported as such (RunResult::succeeded = false).
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "peer_result.hpp"

namespace nonsep::bench {

template <class P>
class GslFixedStep {
 public:
  // `method` is gsl_odeiv2_step_rk2imp or gsl_odeiv2_step_rk4imp (any odeiv2 step type works).
  GslFixedStep(const gsl_odeiv2_step_type* method, double tolerance) {
    system_ = gsl_odeiv2_system{&hamilton_equations, &jacobian, 2, &counts_};
    driver_ = gsl_odeiv2_driver_alloc_y_new(&system_, method, 1e-3, tolerance, 0.0);
    if (driver_ == nullptr) throw std::runtime_error("gsl_odeiv2_driver_alloc_y_new failed");
  }
  GslFixedStep(const GslFixedStep&) = delete;  // GSL keeps pointers to system_ and counts_
  GslFixedStep& operator=(const GslFixedStep&) = delete;
  ~GslFixedStep() { gsl_odeiv2_driver_free(driver_); }

  // `steps` fixed steps of h = t_end / steps from (q0, p0).
  RunResult run(double q0, double p0, double t_end, std::size_t steps) {
    counts_ = Counts{};
    gsl_odeiv2_driver_reset(driver_);
    double y[2] = {q0, p0};
    double t = 0.0;
    const int status = gsl_odeiv2_driver_apply_fixed_step(driver_, &t, t_end / static_cast<double>(steps),
                                                          static_cast<unsigned long>(steps), y);
    RunResult result;
    result.q = y[0];
    result.p = y[1];
    result.evaluations = counts_.rhs;
    result.jacobian_evaluations = counts_.jacobian;
    result.succeeded = status == GSL_SUCCESS;
    return result;
  }

 private:
  struct Counts {
    std::uint64_t rhs = 0, jacobian = 0;
  };
  static int hamilton_equations(double /*t*/, const double y[], double dydt[], void* counts) {
    ++static_cast<Counts*>(counts)->rhs;
    dydt[0] = P::dH_dp(y[0], y[1]);
    dydt[1] = -P::dH_dq(y[0], y[1]);
    return GSL_SUCCESS;
  }
  static int jacobian(double /*t*/, const double y[], double* dfdy, double dfdt[], void* counts) {
    ++static_cast<Counts*>(counts)->jacobian;
    const auto J = P::jacobian(y[0], y[1]);
    for (int i = 0; i < 4; ++i) dfdy[i] = J[static_cast<std::size_t>(i)];
    dfdt[0] = dfdt[1] = 0.0;
    return GSL_SUCCESS;
  }

  Counts counts_;
  gsl_odeiv2_system system_{};
  gsl_odeiv2_driver* driver_ = nullptr;
};

}  // namespace nonsep::bench
