#pragma once
// An independent reference: Hamilton's equations of a full Hamiltonian H(q, p) integrated by Boost.Odeint's
// controlled Runge-Kutta-Fehlberg 7(8) at tight tolerance. Used where no closed-form solution exists.
#include <array>
#include <boost/numeric/odeint.hpp>
#include <vector>

namespace nonsep::reference {

// `rhs(x, dxdt)` writes (dH/dp, -dH/dq) for x = (q..., p...). Returns x at t_end.
template <class Rhs>
std::vector<double> hamiltonian_flow(Rhs rhs, std::vector<double> x, double t_end, double tolerance = 1e-14) {
  namespace odeint = boost::numeric::odeint;
  auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<std::vector<double>>());
  odeint::integrate_adaptive(
      stepper, [&](const std::vector<double>& s, std::vector<double>& d, double) { rhs(s, d); }, x, 0.0, t_end,
      t_end / 1000);
  return x;
}

// The same flow sampled: x at t = k tau for k = 0 .. count-1 (the first is x itself), the stepper landing on each
// sample time (Odeint's integrate_times), so no interpolation error enters.
template <class Rhs>
std::vector<std::vector<double>> hamiltonian_flow_samples(Rhs rhs, std::vector<double> x, double tau, std::size_t count,
                                                          double tolerance = 1e-14) {
  namespace odeint = boost::numeric::odeint;
  auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<std::vector<double>>());
  std::vector<double> times(count);
  for (std::size_t k = 0; k < count; ++k) times[k] = static_cast<double>(k) * tau;
  std::vector<std::vector<double>> samples;
  samples.reserve(count);
  odeint::integrate_times(
      stepper, [&](const std::vector<double>& s, std::vector<double>& d, double) { rhs(s, d); }, x, times.begin(),
      times.end(), tau / 10, [&](const std::vector<double>& s, double) { samples.push_back(s); });
  return samples;
}

}  // namespace nonsep::reference
