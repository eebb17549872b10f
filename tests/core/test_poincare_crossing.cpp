// The crossing locator: the located point is on the plane to round-off and on the numerical flow (the same scheme
// in fine steps), for forward and backward steps, several schemes, and planes mixing q and p; bad input refused.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/analysis/poincare_crossing.hpp"
#include "support/models.hpp"

namespace test_poincare_crossing {

using namespace nonsep;
using nonsep::testing::Paper1D;
using nonsep::testing::Paper2D;

namespace {

double distance(const std::vector<double>& a, std::span<const double> b) {
  double squared = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) squared += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(squared);
}

// Steps `x` with `spec` until s changes sign `crossings` times, locating each crossing; checks each against the
// plane and against a fine-step run of the same scheme from the step before. Returns the crossings found.
template <class M>
int check_crossings(const M& model, const IntegratorSpec& spec, PhaseSpaceBatch x, double dt, const SectionPlane& plane,
                    int crossings) {
  Integrator integrator(spec);
  PoincareCrossingLocator<Integrator> locator(Integrator{spec});
  SectionCrossing crossing;
  int found = 0;
  double t = 0.0;
  for (int step = 0; step < 200000 && found < crossings; ++step) {
    const PhaseSpaceBatch before = x;
    const double s_before = plane.distance(x.q(), x.p());
    integrator.step(model, x, dt);
    if ((s_before < 0.0) == (plane.distance(x.q(), x.p()) < 0.0)) {
      t += dt;
      continue;
    }
    locator.locate(model, before.q(), before.p(), t, dt, plane, crossing);
    ++found;
    CAPTURE(found);
    // On the plane, to round-off.
    CHECK(std::abs(crossing.distance) <= 1e-12 * plane.scale(crossing.q, crossing.p));
    CHECK(crossing.distance == plane.distance(crossing.q, crossing.p));
    const double tau = crossing.time - t;
    CHECK(tau / dt > 0.0);
    CHECK(tau / dt <= 1.0);
    // On the numerical flow: the same scheme from the step before in 64 steps of tau/64. The two differ by the
    // scheme's error over tau, bounded here by its error over the whole step dt (coarse against fine).
    PhaseSpaceBatch fine = before, fine_step = before, coarse_step = before;
    Integrator fine_integrator(spec);
    for (int k = 0; k < 64; ++k) fine_integrator.step(model, fine, tau / 64);
    for (int k = 0; k < 64; ++k) fine_integrator.step(model, fine_step, dt / 64);
    Integrator(spec).step(model, coarse_step, dt);
    const double step_error =
        std::hypot(distance(std::vector<double>(coarse_step.q().begin(), coarse_step.q().end()), fine_step.q()),
                   distance(std::vector<double>(coarse_step.p().begin(), coarse_step.p().end()), fine_step.p()));
    const double located_error = std::hypot(distance(crossing.q, fine.q()), distance(crossing.p, fine.p()));
    CAPTURE(step_error);
    CHECK(located_error <= 2.0 * step_error + 1e-14);
    CHECK(step_error > 0.0);
    t += dt;
  }
  return found;
}

}  // namespace

TEST_CASE("crossings of q1 = 0 on paper2d lie on the plane to round-off and on the numerical flow") {
  const auto start = PhaseSpaceBatch::single(std::vector{-0.75, 0.3}, std::vector{-1.5, 0.2});
  const SectionPlane q1_zero({1.0, 0.0, 0.0, 0.0}, 0.0);
  CHECK(check_crossings(Paper2D{}, IntegratorSpec{"mpe", ChinOptions{Fraction(4)}}, start, 2e-3, q1_zero, 20) == 20);
  // Triplet of order 2 needs dt = 1e-3 on this orbit (at 2e-3 its largest basic step overflows).
  CHECK(check_crossings(Paper2D{}, IntegratorSpec{"triplet", ChinOptions{Fraction(2)}}, start, 1e-3, q1_zero, 10) ==
        10);
  // A plane that mixes q and p, with an offset, and steps backwards in time.
  const SectionPlane mixed({0.6, -0.3, 0.5, 0.2}, 0.1);
  CHECK(check_crossings(Paper2D{}, IntegratorSpec{"mpe", ChinOptions{Fraction(4)}}, start, -2e-3, mixed, 20) == 20);
}

TEST_CASE("crossings of q = 0 by the basic step on paper1d, where H fixes p at the crossing") {
  // H_TTV = (1 + p^2/2)^2 (1 + q^2) = (1 + p^2/2)^2 at q = 0: the crossing has |p| = sqrt(2 (sqrt(H) - 1)), up to
  // the basic step's error, O(dt^(2/3)) (2e-3 relative measured at dt = 1e-3).
  const auto start = PhaseSpaceBatch::single(std::vector{1.3}, std::vector{0.2});
  CHECK(check_crossings(Paper1D{}, IntegratorSpec{}, start, 1e-3, SectionPlane({1.0, 0.0}, 0.0), 6) == 6);
  const double h = Paper1D::H_TTV(1.3, 0.2), expected = std::sqrt(2.0 * (std::sqrt(h) - 1.0));
  PoincareCrossingLocator<> locator;
  SectionCrossing crossing;
  auto x = start;
  Integrator integrator{IntegratorSpec{}};
  for (int step = 0; step < 100000; ++step) {
    const auto before = x;
    integrator.step(Paper1D{}, x, 1e-3);
    if ((before.q()[0] < 0.0) != (x.q()[0] < 0.0)) {
      locator.locate(Paper1D{}, before.q(), before.p(), step * 1e-3, 1e-3, SectionPlane({1.0, 0.0}, 0.0), crossing);
      break;
    }
  }
  CHECK(std::abs(crossing.q[0]) < 1e-15);
  CHECK(std::abs(std::abs(crossing.p[0]) - expected) < 1e-2 * expected);
  CHECK(crossing.steps < 30);
}

TEST_CASE("the crossing locator refuses a step without a crossing and a bad plane") {
  PoincareCrossingLocator<> locator;
  SectionCrossing crossing;
  const std::vector<double> q{0.5}, p{0.1};
  std::string message;
  try {
    locator.locate(Paper1D{}, q, p, 0.0, 1e-3, SectionPlane({1.0, 0.0}, 0.0), crossing);
  } catch (const InvalidArgument& e) {
    message = e.what();
  }
  CHECK(message.find("no crossing in this step, s goes from 0.5") != std::string::npos);
  CHECK_THROWS_AS(SectionPlane({0.0, 0.0}, 0.0), InvalidArgument);
  CHECK_THROWS_AS(SectionPlane({1.0, 0.0, 0.0}, 0.0), InvalidArgument);
  CHECK_THROWS_AS(locator.locate(Paper1D{}, q, p, 0.0, 1e-3, SectionPlane({1.0, 0.0, 0.0, 0.0}, 0.0), crossing),
                  InvalidArgument);
  CHECK_THROWS_AS(locator.locate(Paper1D{}, q, p, 0.0, 0.0, SectionPlane({1.0, 0.0}, 0.0), crossing), InvalidArgument);
}

}  // namespace test_poincare_crossing
