// Measured orders of every scheme of the catalogue on a model with a separable part: the Mathews-Lakshmanan
// oscillator H = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2 / (1 + lambda q^2) = T_i V_ij T_j + U(q), against its
// exact solution (nonsep/reference/mathews_lakshmanan_exact.hpp). Chin's schemes step it through the separable
// composition (separable_composition.hpp, which derives that every order survives); the comparators through the
// full grad H. Each case halves dt over a range inside the asymptotic regime, found by printing the local slopes
// log2(e(dt)/e(dt/2)) from dt = T/4 down to round-off (quoted at each case), and fits the slope of log(error) vs
// log(dt). The last test fails for a catalogue entry without a case.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "nonsep/reference/mathews_lakshmanan_exact.hpp"
#include "support/convergence.hpp"
#include "support/models.hpp"

using namespace nonsep;

namespace {

const double amplitude = 1.5, phase = std::acos(-1.0) / 2.0;  // from (q, p) = (1.5, 0)

struct Study {
  IntegratorSpec spec;
  double nominal;
  int quarters;     // integrate to quarters * (quarter period)
  int first_steps;  // steps over that time at the largest dt; each further dt halves the step
  int halvings;
  // The order from the last two local slopes s1, s2 extrapolated with the next error term's known exponent
  // (n + 2/3: s = n + c dt^(2/3), so n = (s2 - r s1) / (1 - r), r = 2^(-2/3)), instead of the fitted slope.
  bool extrapolate = false;
};

double measured_order(const Study& study) {
  const reference::MathewsLakshmanan exact;
  const double t_end = exact.period(amplitude) / 4.0 * study.quarters;
  const auto end = exact.at(amplitude, phase, t_end);
  const testing::MathewsLakshmanan model;
  std::vector<double> dts, errors;
  for (int h = 0, steps = study.first_steps; h <= study.halvings; ++h, steps *= 2) {
    Integrator integrator(study.spec);
    const double q[] = {amplitude}, p[] = {0.0};
    auto x = PhaseSpaceBatch::single(q, p);
    const double dt = t_end / steps;
    integrator.step_n(model, x, dt, static_cast<std::uint64_t>(steps));
    dts.push_back(dt);
    errors.push_back(std::hypot(x.q()[0] - end.q, x.p()[0] - end.p));
  }
  double n = testing::fitted_exponent(dts, errors);
  if (study.extrapolate) {
    const std::size_t k = errors.size();
    const double s1 = std::log2(errors[k - 3] / errors[k - 2]), s2 = std::log2(errors[k - 2] / errors[k - 1]);
    const double r = std::pow(2.0, -2.0 / 3.0);
    MESSAGE("local slopes " << s1 << ", " << s2 << "; fitted exponent " << n);
    n = (s2 - r * s1) / (1.0 - r);
  }
  MESSAGE(study.spec.scheme << " " << Integrator(study.spec).describe().order.to_string() << " (t2 " << study.spec.t2
                            << "): measured " << n << " for dt from " << dts.front() << " to " << dts.back()
                            << ", errors " << errors.front() << " to " << errors.back());
  return n;
}

IntegratorSpec chin(const char* scheme, Fraction order, double t2 = ChinCoefficients::default_t2()) {
  return {scheme, order, t2};
}
IntegratorSpec tao(int order) { return {"tao", Fraction(order)}; }
IntegratorSpec gauss(int stages) {
  IntegratorSpec spec{"gauss"};
  spec.stages = stages;
  return spec;
}

const std::vector<Study>& order_cases() {
  static const std::vector<Study> cases = {
      // basic: slopes 0.674, 0.671, 0.669, 0.668 for dt = T/1024 .. T/16384 (T the quarter period).
      {chin("basic", Fraction(2, 3)), 2.0 / 3, 1, 1024, 4},
      // triplet 4/3: slopes 1.353, 1.345, 1.341 for T/1024 .. T/8192.
      {chin("triplet", Fraction(4, 3)), 4.0 / 3, 1, 1024, 3},
      // triplet 2: slopes 2.095, 2.060, 2.038 for T/2048 .. T/16384.
      {chin("triplet", Fraction(2)), 2.0, 1, 2048, 3},
      // triplet 8/3, where the separable part's dt^3 error term is cancelled: slopes 2.713, 2.695 for T/4096 ..
      // T/16384.
      {chin("triplet", Fraction(8, 3)), 8.0 / 3, 1, 4096, 2},
      // triplet 10/3 (t2 = -1.2, whose next error term is small): slopes 3.346, 3.340 for T/2048 .. T/8192.
      {chin("triplet", Fraction(10, 3), -1.2), 10.0 / 3, 1, 2048, 2},
      // mpe 4/3: slopes 1.346, 1.341, 1.338 for T/512 .. T/4096.
      {chin("mpe", Fraction(4, 3)), 4.0 / 3, 1, 512, 3},
      // mpe 2: slopes 2.041, 2.026, 2.016 for T/512 .. T/4096.
      {chin("mpe", Fraction(2)), 2.0, 1, 512, 3},
      // mpe 8/3, the separable dt^3 term cancelled by the weights: slopes 2.723, 2.702, 2.689 for T/256 .. T/2048.
      {chin("mpe", Fraction(8, 3)), 8.0 / 3, 1, 256, 3},
      // mpe 10/3 (t2 = -1.2): slopes 3.392, 3.372 for T/256 .. T/1024 (round-off near 1e-11 below).
      {chin("mpe", Fraction(10, 3), -1.2), 10.0 / 3, 1, 256, 2},
      // mpe 4 (six terms): the slope approaches 4 from above as 4 + c dt^(2/3) and meets round-off (~5e-12, the
      // weights up to 645) first: slopes 4.39, 4.25, 4.16 for T/32 .. T/256 (t2 = -1.5; 2.3 at T/512), which
      // extrapolate to 4.01.
      {chin("mpe", Fraction(4), -1.5), 4.0, 1, 32, 3, true},
      // tao 2 (omega = 20): slopes 2.013, 2.003, 2.001 for T/64 .. T/512.
      {tao(2), 2.0, 1, 64, 3},
      // tao 4: slopes 4.085, 4.029, 4.008 for T/64 .. T/512.
      {tao(4), 4.0, 1, 64, 3},
      // tao 6: slopes 5.924, 5.981 for T/256 .. T/1024, then round-off near 1e-14.
      {tao(6), 6.0, 1, 256, 2},
      // implicit midpoint and gauss 1: slopes 2.007, 2.002, 2.000, 2.000 for T/8 .. T/128.
      {IntegratorSpec{"implicit_midpoint"}, 2.0, 1, 8, 4},
      {gauss(1), 2.0, 1, 8, 4},
      // gauss 2: slopes 4.024, 4.006, 4.001 for T/16 .. T/128.
      {gauss(2), 4.0, 1, 16, 3},
      // gauss 3: slopes 6.118, 6.027, 6.006 for T/8 .. T/64.
      {gauss(3), 6.0, 1, 8, 3},
  };
  return cases;
}

void check_cases_of(const std::string& scheme) {
  int cases = 0;
  for (const Study& study : order_cases())
    if (study.spec.scheme == scheme) {
      ++cases;
      CAPTURE(Integrator(study.spec).describe().order.to_string());
      CHECK(std::abs(measured_order(study) - study.nominal) < 0.1);
    }
  CHECK(cases > 0);
}

}  // namespace

TEST_CASE("Mathews-Lakshmanan: the exact solution against Hamilton's equations integrated by RKF 7(8)") {
  const reference::MathewsLakshmanan exact;
  const double lambda = exact.lambda, alpha = exact.alpha;
  auto rhs = [&](const std::vector<double>& s, std::vector<double>& d) {
    const double q = s[0], p = s[1], m = 1.0 + lambda * q * q;
    d[0] = m * p;
    d[1] = -lambda * q * p * p - alpha * alpha * q / (m * m);
  };
  const double t = 0.8 * exact.period(amplitude);
  const auto end = reference::hamiltonian_flow(rhs, {amplitude, 0.0}, t);
  const auto expected = exact.at(amplitude, phase, t);
  CHECK(std::abs(end[0] - expected.q) < 1e-11);
  CHECK(std::abs(end[1] - expected.p) < 1e-11);
  CHECK(exact.hamiltonian(expected.q, expected.p) == doctest::Approx(exact.energy(amplitude)).epsilon(1e-14));
  // The product form and U of the test model give the same H.
  const testing::MathewsLakshmanan model;
  const double q[] = {0.7}, p[] = {-0.4};
  EnergyEvaluator energy(HamiltonianForm::TTV);
  CHECK(energy.evaluate_one(model, PhaseSpaceBatch::single(q, p)) ==
        doctest::Approx(exact.hamiltonian(0.7, -0.4)).epsilon(1e-15));
}

TEST_CASE("separable part: the basic step converges with order 2/3") { check_cases_of("basic"); }

TEST_CASE("separable part: triplet composition converges with orders 4/3, 2, 8/3 and 10/3") {
  check_cases_of("triplet");
}

TEST_CASE("separable part: multi-product expansion converges with orders 4/3, 2, 8/3, 10/3 and 4") {
  check_cases_of("mpe");
}

TEST_CASE("separable part: comparators tao 2, 4, 6, implicit midpoint, gauss with 1, 2, 3 stages") {
  for (const char* scheme : {"tao", "implicit_midpoint", "gauss"}) {
    CAPTURE(scheme);
    check_cases_of(scheme);
  }
}

TEST_CASE("separable part: every scheme of the catalogue, every order of a comparator, has an order case") {
  for (const auto& scheme : scheme_catalogue()) {
    CAPTURE(scheme.name);
    std::vector<Fraction> covered;
    for (const Study& study : order_cases())
      if (study.spec.scheme == scheme.name) covered.push_back(Integrator(study.spec).describe().order);
    CHECK_MESSAGE(!covered.empty(), "no order case for the catalogue scheme " << scheme.name);
    if (scheme.family == "comparator")
      for (const Fraction& order : scheme.orders()) {
        CAPTURE(order.to_string());
        CHECK(std::find(covered.begin(), covered.end(), order) != covered.end());
      }
  }
}
