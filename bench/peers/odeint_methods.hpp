#pragma once
// Boost.Odeint peers on Hamilton's equations of the full H of a problem (benchmark_problems.hpp):
// classical Runge-Kutta 4 at a fixed step, and Dormand-Prince 5(4) with step-size control at a tolerance.
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cstddef>
#include <cstdint>

#include "peer_result.hpp"

namespace nonsep::bench {

using OdeintState = std::array<double, 2>;  // (q, p)

// Hamilton's equations of P, counting its evaluations.
template <class P>
struct CountedHamiltonEquations {
  std::uint64_t* count;
  void operator()(const OdeintState& x, OdeintState& dxdt, double /*t*/) const {
    ++*count;
    dxdt[0] = P::dH_dp(x[0], x[1]);
    dxdt[1] = -P::dH_dq(x[0], x[1]);
  }
};

// `steps` steps of runge_kutta4 with dt = t_end / steps.
template <class P>
RunResult odeint_runge_kutta4(double q0, double p0, double t_end, std::size_t steps) {
  namespace odeint = boost::numeric::odeint;
  RunResult result;
  OdeintState x{q0, p0};
  odeint::runge_kutta4<OdeintState> stepper;
  const double dt = t_end / static_cast<double>(steps);
  double t = 0.0;
  const CountedHamiltonEquations<P> system{&result.evaluations};
  for (std::size_t i = 0; i < steps; ++i, t += dt) stepper.do_step(system, x, t, dt);
  result.q = x[0];
  result.p = x[1];
  return result;
}

// runge_kutta_dopri5 under odeint's standard error control with absolute and relative tolerance `tolerance`,
// driven by integrate_adaptive exactly to t_end (its last step is shortened to land on t_end).
template <class P>
RunResult odeint_dopri5(double q0, double p0, double t_end, double tolerance) {
  namespace odeint = boost::numeric::odeint;
  RunResult result;
  OdeintState x{q0, p0};
  auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<OdeintState>());
  odeint::integrate_adaptive(stepper, CountedHamiltonEquations<P>{&result.evaluations}, x, 0.0, t_end, t_end / 100.0);
  result.q = x[0];
  result.p = x[1];
  return result;
}

}  // namespace nonsep::bench
