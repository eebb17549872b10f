// The comparator schemes (Tao's extended phase space, Gauss-Legendre collocation): the gradient of the solved H
// against finite differences, and measured orders of convergence against exact and independent references, as
// test_core_convergence.cpp does for Chin's schemes. Each dt range was chosen inside the asymptotic regime by
// printing the local slopes log2(e(dt)/e(dt/2)) from large dt down to round-off (quoted at each case).
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "support/convergence.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"

namespace test_comparators_convergence {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;

namespace {

// Steps a single state from (q0, p0) by `steps` steps of dt with a fresh stepper made by `make`.
using Run = std::function<PhaseSpaceBatch(double q0, double p0, double dt, int steps)>;

template <class Stepper>
Run run_with(std::function<Stepper()> make) {
  return [make](double q0, double p0, double dt, int steps) {
    Stepper stepper = make();
    const double q[] = {q0}, p[] = {p0};
    auto x = PhaseSpaceBatch::single(q, p);
    for (int s = 0; s < steps; ++s) stepper.step(Paper1D{}, x, dt);
    return x;
  };
}

// Fitted exponent of the error against (q_end, p_end) after t_end, for steps = first, 2 first, ... (halvings + 1).
double measured_order(const std::string& name, const Run& run, double q0, double p0, double t_end, double q_end,
                      double p_end, int first_steps, int halvings) {
  std::vector<double> dts, errors;
  for (int h = 0, steps = first_steps; h <= halvings; ++h, steps *= 2) {
    const auto x = run(q0, p0, t_end / steps, steps);
    dts.push_back(t_end / steps);
    errors.push_back(std::hypot(x.q()[0] - q_end, x.p()[0] - p_end));
  }
  std::ostringstream slopes;
  for (std::size_t i = 1; i < errors.size(); ++i) slopes << ' ' << std::log2(errors[i - 1] / errors[i]);
  const double n = nonsep::testing::fitted_exponent(dts, errors);
  MESSAGE(name << ": fitted exponent " << n << " for dt from " << dts.front() << " to " << dts.back() << ", errors "
               << errors.front() << " to " << errors.back() << ", local slopes" << slopes.str());
  return n;
}

}  // namespace

TEST_CASE("the gradient of H is the derivative of the energy, both forms") {
  // Central differences of H (EnergyEvaluator, itself checked against closed forms in test_core_properties.cpp).
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(static_cast<int>(form));
    EnergyEvaluator energy(form);
    HamiltonianGradient gradient(form);
    const std::vector<double> q{0.4, -0.7, 1.1, 0.3}, p{0.2, 0.5, -0.6, 0.9};  // two states of Coupled2D
    std::vector<double> dq(4), dp(4);
    gradient.evaluate(Coupled2D{}, q, p, dq, dp, 2);
    CHECK(gradient.evaluations().grad_H == 2);
    const double h = 1e-6;
    for (std::size_t b = 0; b < 2; ++b)
      for (std::size_t k = 0; k < 2; ++k)
        for (const bool in_q : {true, false}) {
          auto at = [&](double shift) {
            std::vector<double> qs{q[2 * b], q[2 * b + 1]}, ps{p[2 * b], p[2 * b + 1]};
            (in_q ? qs : ps)[k] += shift;
            return energy.evaluate_one(Coupled2D{}, PhaseSpaceBatch::single(qs, ps));
          };
          const double difference = nonsep::testing::central_difference(at, 0.0, h);
          CHECK(std::abs(difference - (in_q ? dq : dp)[2 * b + k]) < 1e-8);
        }
  }
  // Paper1D: dH_TTV/dq = 2 q (1 + p^2/2)^2, dH_TTV/dp = 2 p (1 + p^2/2)(1 + q^2); H_VVT = (q + q^3/3)^2 p.
  const double q = 1.3, p = -0.7, u = 1.0 + p * p / 2, w = q + q * q * q / 3;
  std::vector<double> dq(1), dp(1);
  HamiltonianGradient ttv(HamiltonianForm::TTV), vvt(HamiltonianForm::VVT);
  ttv.evaluate(Paper1D{}, std::vector<double>{q}, std::vector<double>{p}, dq, dp, 1);
  CHECK(dq[0] == doctest::Approx(2 * q * u * u).epsilon(1e-15));
  CHECK(dp[0] == doctest::Approx(2 * p * u * (1 + q * q)).epsilon(1e-15));
  vvt.evaluate(Paper1D{}, std::vector<double>{q}, std::vector<double>{p}, dq, dp, 1);
  CHECK(dq[0] == doctest::Approx(2 * w * (1 + q * q) * p).epsilon(1e-15));
  CHECK(dp[0] == doctest::Approx(w * w).epsilon(1e-15));
  CHECK_THROWS_AS(ttv.evaluate(Paper1D{}, std::vector<double>{q}, std::vector<double>{p}, dq, dp, 2), InvalidArgument);
}

// The orders on the exact quarter period of paper1d (tao 2, 4, 6; implicit midpoint; gauss 1, 2, 3 stages) are
// measured with every other scheme of the catalogue in test_core_convergence.cpp.

TEST_CASE("the VVT form: both comparators converge to the flow of H_VVT = (q + q^3/3)^2 p") {
  // The reference of test_core_properties.cpp: Hamilton's equations by Runge-Kutta-Fehlberg 7(8).
  auto rhs = [](const std::vector<double>& s, std::vector<double>& d) {
    const double q = s[0], p = s[1], w = q + q * q * q / 3.0;
    d[0] = w * w;
    d[1] = -2.0 * w * (1.0 + q * q) * p;
  };
  const double t_end = 0.5;
  const auto reference = nonsep::reference::hamiltonian_flow(rhs, {0.5, 0.5}, t_end);
  const auto tao = run_with<TaoExtendedPhaseSpace>([] { return TaoExtendedPhaseSpace(HamiltonianForm::VVT, 4); });
  const auto gauss = run_with<GaussLegendre>([] { return GaussLegendre(HamiltonianForm::VVT, 4); });
  // Slopes from 4 steps up: tao 4.16, 3.74, 3.77, 3.92, 3.98, 3.995, 3.9986 (64 .. 512 steps used);
  // gauss 3.96, 3.99, 3.998, 3.9993, 3.9986 (8 .. 64 steps used).
  CHECK(std::abs(measured_order("tao 4 VVT", tao, 0.5, 0.5, t_end, reference[0], reference[1], 64, 3) - 4.0) < 0.1);
  CHECK(std::abs(measured_order("gauss 4 VVT", gauss, 0.5, 0.5, t_end, reference[0], reference[1], 8, 3) - 4.0) < 0.1);
}

}  // namespace test_comparators_convergence
