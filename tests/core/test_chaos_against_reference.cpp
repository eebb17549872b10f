// Lyapunov exponents and MEGNO of whole orbits: integrable models (the exponent decays like log(t)/t, <Y> -> 2)
// and the chaotic and regular orbits of paper2d, the chaotic one's finite-time exponent against the variational
// equations of H_TTV integrated by Runge-Kutta-Fehlberg 7(8) (reference/variational_flow.hpp).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/analysis/megno.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/reference/variational_flow.hpp"
#include "support/convergence.hpp"
#include "support/models.hpp"

namespace test_chaos_against_reference {

using namespace nonsep;
using nonsep::testing::Paper1D;
using nonsep::testing::Paper2D;
using nonsep::testing::Radial2D;

namespace {

// One trajectory with its first tangent vector (k = 1), renormalised every 10 steps; records the finite-time
// exponent ln|delta(t)|/t and <Y>(t) at each renormalisation.
struct Orbit {
  std::vector<double> times, exponents, mean_y;
};

template <class M>
Orbit follow(const M& model, const IntegratorSpec& spec, std::vector<double> q, std::vector<double> p,
             const std::vector<double>& delta, double dt, int steps) {
  const std::size_t n = q.size();
  TangentIntegrator integrator(spec);
  LyapunovExponents lyapunov(1, 10);
  auto x = PhaseSpaceBatch::single(q, p);
  PhaseSpaceBatch tangents(n, 1);
  std::copy_n(delta.begin(), n, tangents.q().begin());
  std::copy_n(delta.begin() + static_cast<std::ptrdiff_t>(n), n, tangents.p().begin());
  std::array<LyapunovRecord, 1> record{};
  const MegnoIndicator megno;
  std::vector<double> megno_state(MegnoIndicator::state_numbers);
  std::array<double, 1> growth{};
  std::array<double, 2> y{};
  lyapunov.start(tangents, record);
  megno.start(megno_state);
  Orbit orbit;
  for (int s = 1; s <= steps; ++s) {
    integrator.step(model, x, tangents, dt);
    lyapunov.after_step(tangents, record, dt, growth);
    megno.after_step(megno_state, growth[0], dt);
    if (record[0].steps_since_renormalization == 0) {
      orbit.times.push_back(record[0].time);
      orbit.exponents.push_back(record[0].exponent(0));
      megno.values(megno_state, record[0], y);
      orbit.mean_y.push_back(y[1]);
    }
  }
  return orbit;
}

// Slope of ln|delta(t)| = lambda(t) t against ln t over the second half of the run (1 for linear growth).
double growth_power(const Orbit& orbit) {
  std::vector<double> t, size;
  for (std::size_t i = orbit.times.size() / 2; i < orbit.times.size(); ++i) {
    t.push_back(orbit.times[i]);
    size.push_back(std::exp(orbit.exponents[i] * orbit.times[i]));
  }
  return nonsep::testing::fitted_exponent(t, size);
}

// The generic initial tangent vectors of these tests: (dq, dp) = (1, 0.5) in 1D, (1, 0.5, -0.3, 0.7) in 2D, not
// along the flow nor along the gradient of H, so that the shear between neighbouring tori shows.
const std::vector<double> delta1{1.0, 0.5}, delta2{1.0, 0.5, -0.3, 0.7};
// Symplectic, for the integrable models. On paper2d's high-energy orbits its largest basic step (6.4 dt) overflows
// at dt = 2e-3.
const IntegratorSpec triplet2{"triplet", ChinOptions{Fraction(2)}};
// Order 4, 21 basic steps per step: on paper2d at dt = 2e-3 within 2e-4 of the flow at t = 15 (triplet of order 2
// at dt = 2.5e-4 is 6e-3 away at t = 1), which a finite-time exponent of a chaotic orbit needs.
const IntegratorSpec mpe4{"mpe", ChinOptions{Fraction(4)}};

}  // namespace

TEST_CASE("integrable paper1d: the exponent decays like log(t)/t and <Y> tends to 2") {
  const Orbit orbit = follow(Paper1D{}, triplet2, {1.0}, {0.3}, delta1, 0.01, 100000);
  MESSAGE("paper1d: lambda(t = " << orbit.times.back() << ") = " << orbit.exponents.back()
                                 << ", <Y> = " << orbit.mean_y.back() << ", |delta| ~ t^" << growth_power(orbit));
  CHECK(std::abs(growth_power(orbit) - 1.0) < 0.1);
  CHECK(orbit.exponents.back() < 2.0 * std::log(orbit.times.back()) / orbit.times.back());
  CHECK(orbit.mean_y.back() == doctest::Approx(2.0).epsilon(0.05));
}

TEST_CASE("integrable radial model in 2D with angular momentum: the exponent decays like log(t)/t and <Y> -> 2") {
  // q x p = 0.8 != 0 keeps |p| >= 0.8/|q| away from 0, where the model is undefined.
  const Orbit orbit = follow(Radial2D{}, triplet2, {1.0, 0.0}, {0.2, 0.8}, delta2, 0.002, 200000);
  MESSAGE("radial: lambda(t = " << orbit.times.back() << ") = " << orbit.exponents.back()
                                << ", <Y> = " << orbit.mean_y.back() << ", |delta| ~ t^" << growth_power(orbit));
  CHECK(std::abs(growth_power(orbit) - 1.0) < 0.1);
  CHECK(orbit.exponents.back() < 2.0 * std::log(orbit.times.back()) / orbit.times.back());
  CHECK(orbit.mean_y.back() == doctest::Approx(2.0).epsilon(0.05));
}

TEST_CASE("paper2d has regular and chaotic orbits at about the same energy") {
  const Orbit regular = follow(Paper2D{}, mpe4, {0.25, 0.3}, {-1.5, 0.2}, delta2, 0.002, 50000);
  const Orbit chaotic = follow(Paper2D{}, mpe4, {-0.75, 0.3}, {-1.5, 0.2}, delta2, 0.002, 50000);
  MESSAGE("paper2d at t = " << regular.times.back() << ": regular lambda " << regular.exponents.back() << " <Y> "
                            << regular.mean_y.back() << "; chaotic lambda " << chaotic.exponents.back() << " <Y> "
                            << chaotic.mean_y.back());
  CHECK(regular.mean_y.back() == doctest::Approx(2.0).epsilon(0.1));
  CHECK(chaotic.exponents.back() > 0.15);
  // <Y> grows like lambda t / 2 on the chaotic orbit.
  CHECK(chaotic.mean_y.back() > 0.5 * chaotic.exponents.back() * chaotic.times.back() / 2.0);
}

TEST_CASE("paper2d, chaotic orbit: the finite-time exponent agrees with the variational equations within 1%") {
  const std::vector<double> q{-0.75, 0.3}, p{-1.5, 0.2};
  const reference::VariationalFlow<4, Paper2D> flow(Paper2D{});
  std::array<double, 4> x{q[0], q[1], p[0], p[1]}, delta{delta2[0], delta2[1], delta2[2], delta2[3]};
  const std::vector<double> times{5.0, 10.0, 15.0, 20.0};
  const auto expected = flow.finite_time_exponents(x, delta, times);
  const Orbit orbit = follow(Paper2D{}, mpe4, q, p, delta2, 2e-3, 10000);
  for (std::size_t i = 0; i < times.size(); ++i) {
    const auto at = static_cast<std::size_t>(std::lround(times[i] / 2e-2)) - 1;  // renormalised every 10 steps
    CAPTURE(times[i]);
    REQUIRE(orbit.times[at] == doctest::Approx(times[i]).epsilon(1e-12));
    MESSAGE("t = " << times[i] << ": map " << orbit.exponents[at] << ", reference " << expected[i]);
    CHECK(orbit.exponents[at] == doctest::Approx(expected[i]).epsilon(0.01));
  }
  CHECK(expected.back() > 0.1);
}

TEST_CASE("paper2d, chaotic orbit: the long-time exponent lies within the spread of nearby starts") {
  // At t = 100 neighbouring orbits have long separated (lambda t ~ 40), so the map and the flow are compared as
  // ensembles: the map's exponent of the orbit must lie within three standard deviations of the mean of the
  // reference exponents of 8 starts displaced by 1e-3 in q.
  const double t_end = 100.0;
  const Orbit orbit = follow(Paper2D{}, mpe4, {-0.75, 0.3}, {-1.5, 0.2}, delta2, 2e-3, 50000);
  const reference::VariationalFlow<4, Paper2D> flow(Paper2D{}, 1e-11);
  std::vector<double> exponents;
  for (int k = 0; k < 8; ++k) {
    const double angle = 2.0 * std::numbers::pi * k / 8.0;
    std::array<double, 4> x{-0.75 + 1e-3 * std::cos(angle), 0.3 + 1e-3 * std::sin(angle), -1.5, 0.2};
    std::array<double, 4> delta{delta2[0], delta2[1], delta2[2], delta2[3]};
    exponents.push_back(flow.finite_time_exponents(x, delta, {t_end})[0]);
  }
  const double mean = std::accumulate(exponents.begin(), exponents.end(), 0.0) / 8.0;
  double variance = 0.0;
  for (double e : exponents) variance += (e - mean) * (e - mean) / 7.0;
  const double spread = std::sqrt(variance);
  MESSAGE("t = " << t_end << ": map " << orbit.exponents.back() << "; nearby starts (reference) " << mean << " +- "
                 << spread);
  CHECK(mean > 0.1);
  CHECK(std::abs(orbit.exponents.back() - mean) < 3.0 * spread);
}

}  // namespace test_chaos_against_reference
