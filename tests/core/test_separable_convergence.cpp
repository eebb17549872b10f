// Measured orders of every scheme of the catalogue on models with a separable part. The Mathews-Lakshmanan
// oscillator H = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2 / (1 + lambda q^2) = T_i V_ij T_j + U(q), against its
// exact solution (nonsep/reference/mathews_lakshmanan_exact.hpp): every scheme and order. A 2D model in the VVT form
// with K and U, H = V_i T_ij V_j + K(p) + U(q) (SwappedVariableMass2D), against Hamilton's equations integrated by
// RKF 7(8) at tolerance 1e-14: the basic step, triplet and MPE. Chin's schemes step them through the separable
// composition (separable_composition.hpp, which derives that every order survives); the comparators through the
// full grad H. Each case halves dt over a range inside the asymptotic regime, found by printing the local slopes
// log2(e(dt)/e(dt/2)) from a large dt down to round-off (quoted at each case), and fits the slope of log(error) vs
// log(dt). The last test fails for a catalogue entry without a case.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "nonsep/reference/mathews_lakshmanan_exact.hpp"
#include "support/convergence.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"

namespace test_separable_convergence {

using namespace nonsep;

namespace {

const double amplitude = 1.5, phase = std::acos(-1.0) / 2.0;  // from (q, p) = (1.5, 0)

struct Study {
  IntegratorSpec spec;
  double nominal;
  int first_steps;  // steps over the time of the study at the largest dt; each further dt halves the step
  int halvings;
  // The order from the last two local slopes s1, s2 extrapolated with the next error term's known exponent
  // (n + 2/3: s = n + c dt^(2/3), so n = (s2 - r s1) / (1 - r), r = 2^(-2/3)), instead of the fitted slope.
  bool extrapolate = false;
};

// The order of study.spec measured on `model` from `start` = (q..., p...) to `end`, the state at t_end.
template <class M>
double measured_order(const Study& study, const M& model, const std::vector<double>& start,
                      const std::vector<double>& end, double t_end) {
  const std::size_t n = start.size() / 2;
  std::vector<double> dts, errors;
  for (int h = 0, steps = study.first_steps; h <= study.halvings; ++h, steps *= 2) {
    Integrator integrator(study.spec);
    auto x = PhaseSpaceBatch::single(std::span(start).first(n), std::span(start).subspan(n));
    const double dt = t_end / steps;
    integrator.step_n(model, x, dt, static_cast<std::uint64_t>(steps));
    double error = 0;
    for (std::size_t i = 0; i < n; ++i) error = std::hypot(error, x.q()[i] - end[i], x.p()[i] - end[n + i]);
    dts.push_back(dt);
    errors.push_back(error);
  }
  double order = testing::fitted_exponent(dts, errors);
  if (study.extrapolate) {
    const std::size_t k = errors.size();
    const double s1 = std::log2(errors[k - 3] / errors[k - 2]), s2 = std::log2(errors[k - 2] / errors[k - 1]);
    const double r = std::pow(2.0, -2.0 / 3.0);
    MESSAGE("local slopes " << s1 << ", " << s2 << "; fitted exponent " << order);
    order = (s2 - r * s1) / (1.0 - r);
  }
  MESSAGE(study.spec.scheme << " " << Integrator(study.spec).describe().order.to_string() << " (t2 "
                            << Integrator(study.spec).describe().t2 << "): measured " << order << " for dt from "
                            << dts.front() << " to " << dts.back() << ", errors " << errors.front() << " to "
                            << errors.back());
  return order;
}

// The Mathews-Lakshmanan oscillator from (amplitude, 0) to the quarter period.
double measured_order(const Study& study) {
  const reference::MathewsLakshmanan exact;
  const double t_end = exact.period(amplitude) / 4.0;
  const auto end = exact.at(amplitude, phase, t_end);
  return measured_order(study, testing::MathewsLakshmanan{}, {amplitude, 0.0}, {end.q, end.p}, t_end);
}

IntegratorSpec chin(const char* scheme, Fraction order, double t2 = ChinCoefficients::default_t2()) {
  return {scheme, ChinOptions{order, t2}};
}
IntegratorSpec tao(int order) { return {"tao", TaoOptions{Fraction(order)}}; }
IntegratorSpec gauss(int stages) { return {"gauss", GaussOptions{stages}}; }

const std::vector<Study>& order_cases() {
  static const std::vector<Study> cases = {
      // basic: slopes 0.674, 0.671, 0.669, 0.668 for dt = T/1024 .. T/16384 (T the quarter period).
      {chin("basic", Fraction(2, 3)), 2.0 / 3, 1024, 4},
      // triplet 4/3: slopes 1.353, 1.345, 1.341 for T/1024 .. T/8192.
      {chin("triplet", Fraction(4, 3)), 4.0 / 3, 1024, 3},
      // triplet 2: slopes 2.095, 2.060, 2.038 for T/2048 .. T/16384.
      {chin("triplet", Fraction(2)), 2.0, 2048, 3},
      // triplet 8/3, where the separable part's dt^3 error term is cancelled: slopes 2.713, 2.695 for T/4096 ..
      // T/16384.
      {chin("triplet", Fraction(8, 3)), 8.0 / 3, 4096, 2},
      // triplet 10/3 (t2 = -1.2, whose next error term is small): slopes 3.346, 3.340 for T/2048 .. T/8192.
      {chin("triplet", Fraction(10, 3), -1.2), 10.0 / 3, 2048, 2},
      // triplet 4 (243 basic steps per step; t2 = -2.5): slopes 4.316, 4.200, 4.128, 4.044 for T/1024 .. T/16384,
      // approaching 4 from above as 4 + c dt^(2/3) until round-off (4.5e-13 at T/65536 with the default t2) pulls the
      // last one down; extrapolated from 4.200, 4.128 (errors 2.0e-9 to 1.2e-10, far above round-off) to 4.006.
      {chin("triplet", Fraction(4), -2.5), 4.0, 2048, 2, true},
      // mpe 4/3: slopes 1.346, 1.341, 1.338 for T/512 .. T/4096.
      {chin("mpe", Fraction(4, 3)), 4.0 / 3, 512, 3},
      // mpe 2: slopes 2.041, 2.026, 2.016 for T/512 .. T/4096.
      {chin("mpe", Fraction(2)), 2.0, 512, 3},
      // mpe 8/3, the separable dt^3 term cancelled by the weights: slopes 2.723, 2.702, 2.689 for T/256 .. T/2048.
      {chin("mpe", Fraction(8, 3)), 8.0 / 3, 256, 3},
      // mpe 10/3 (t2 = -1.2): slopes 3.392, 3.372 for T/256 .. T/1024 (round-off near 1e-11 below).
      {chin("mpe", Fraction(10, 3), -1.2), 10.0 / 3, 256, 2},
      // mpe 4 (six terms): the slope approaches 4 from above as 4 + c dt^(2/3) and meets round-off (~5e-12, the
      // weights up to 645) first: slopes 4.39, 4.25, 4.16 for T/32 .. T/256 (t2 = -1.5; 2.3 at T/512), which
      // extrapolate to 4.01.
      {chin("mpe", Fraction(4), -1.5), 4.0, 32, 3, true},
      // tao 2 (omega = 20): slopes 2.013, 2.003, 2.001 for T/64 .. T/512.
      {tao(2), 2.0, 64, 3},
      // tao 4: slopes 4.085, 4.029, 4.008 for T/64 .. T/512.
      {tao(4), 4.0, 64, 3},
      // tao 6: slopes 5.924, 5.981 for T/256 .. T/1024, then round-off near 1e-14.
      {tao(6), 6.0, 256, 2},
      // implicit midpoint and gauss 1: slopes 2.007, 2.002, 2.000, 2.000 for T/8 .. T/128.
      {IntegratorSpec{"implicit_midpoint"}, 2.0, 8, 4},
      {gauss(1), 2.0, 8, 4},
      // gauss 2: slopes 4.024, 4.006, 4.001 for T/16 .. T/128.
      {gauss(2), 4.0, 16, 3},
      // gauss 3: slopes 6.118, 6.027, 6.006 for T/8 .. T/64.
      {gauss(3), 6.0, 8, 3},
      // gauss 4: slopes 8.92, 8.23, 8.09 for T/4 .. T/32, then round-off near 5e-15.
      {gauss(4), 8.0, 16, 1},
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

// SwappedVariableMass2D in the VVT form with K and U, from (0.6, -0.4, 0.3, 0.5) to t = 2.
const std::vector<double> swapped_start{0.6, -0.4, 0.3, 0.5};
const double swapped_t_end = 2.0;

// Hamilton's equations of SwappedVariableMass2D's H, written out: with Q = |q|^2, P = |p|^2, s = q.p,
//   dq/dt = (lambda Q/3 + kappa) p + (2 lambda/3) s q,
//   dp/dt = -(1 + lambda P/3) q - (2 lambda/3) s p - grad U.
void swapped_rhs(const std::vector<double>& x, std::vector<double>& dxdt) {
  const testing::SwappedVariableMass2D m;
  const double q1 = x[0], q2 = x[1], p1 = x[2], p2 = x[3];
  const double q_q = q1 * q1 + q2 * q2, p_p = p1 * p1 + p2 * p2, q_p = q1 * p1 + q2 * p2, c = 2.0 * m.lambda / 3.0;
  dxdt[0] = (m.lambda * q_q / 3.0 + m.kappa) * p1 + c * q_p * q1;
  dxdt[1] = (m.lambda * q_q / 3.0 + m.kappa) * p2 + c * q_p * q2;
  dxdt[2] = -(1.0 + m.lambda * p_p / 3.0) * q1 - c * q_p * p1 - (q1 + 2.0 * m.mu * q1 * q2 * q2);
  dxdt[3] = -(1.0 + m.lambda * p_p / 3.0) * q2 - c * q_p * p2 - (m.omega * m.omega * q2 + 2.0 * m.mu * q1 * q1 * q2);
}

// The end point by RKF 7(8) at tolerance 1e-14 (1e-13 moves it by 1.5e-13, below the smallest error measured).
const std::vector<double>& swapped_end() {
  static const std::vector<double> end = reference::hamiltonian_flow(swapped_rhs, swapped_start, swapped_t_end);
  return end;
}

IntegratorSpec vvt(const char* scheme, Fraction order, double t2 = ChinCoefficients::default_t2()) {
  return {scheme, ChinOptions{order, t2}, HamiltonianForm::VVT};
}

const std::vector<Study>& vvt_cases() {
  static const std::vector<Study> cases = {
      // basic: slopes 0.677, 0.673, 0.671 for dt = t/1024 .. t/8192.
      {vvt("basic", Fraction(2, 3)), 2.0 / 3, 1024, 3},
      // triplet 4/3: slopes 1.359, 1.349, 1.343 for t/512 .. t/4096.
      {vvt("triplet", Fraction(4, 3)), 4.0 / 3, 512, 3},
      // triplet 2: slopes 2.095, 2.062, 2.040 for t/1024 .. t/8192.
      {vvt("triplet", Fraction(2)), 2.0, 1024, 3},
      // triplet 8/3: slopes 2.690, 2.678, 2.672 for t/1024 .. t/8192.
      {vvt("triplet", Fraction(8, 3)), 8.0 / 3, 1024, 3},
      // triplet 10/3 (t2 = -1.2): slopes 3.293, 3.327, 3.338 for t/1024 .. t/8192.
      {vvt("triplet", Fraction(10, 3), -1.2), 10.0 / 3, 1024, 3},
      // mpe 4/3: slopes 1.350, 1.344, 1.340 for t/256 .. t/2048.
      {vvt("mpe", Fraction(4, 3)), 4.0 / 3, 256, 3},
      // mpe 2: slopes 2.063, 2.040, 2.026 for t/256 .. t/2048.
      {vvt("mpe", Fraction(2)), 2.0, 256, 3},
      // mpe 8/3: slopes 2.686, 2.677, 2.672 for t/128 .. t/1024.
      {vvt("mpe", Fraction(8, 3)), 8.0 / 3, 128, 3},
      // mpe 10/3 (t2 = -1.35, whose next error term is small here): slopes 3.276, 3.338, 3.349 for t/64 .. t/512, then
      // round-off near 4e-12 (with t2 = -1.2 the slopes stay near 3.44 down to it).
      {vvt("mpe", Fraction(10, 3), -1.35), 10.0 / 3, 64, 3},
      // mpe 4 (six terms): slopes 4.387, 4.260, 4.182 for t/16 .. t/128, approaching 4 from above as 4 + c dt^(2/3)
      // until round-off (7e-12 at t/256); extrapolated as for the Mathews-Lakshmanan oscillator.
      {vvt("mpe", Fraction(4)), 4.0, 16, 3, true},
  };
  return cases;
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

TEST_CASE("separable part: triplet composition converges with orders 4/3, 2, 8/3, 10/3 and 4") {
  check_cases_of("triplet");
}

TEST_CASE("separable part: multi-product expansion converges with orders 4/3, 2, 8/3, 10/3 and 4") {
  check_cases_of("mpe");
}

TEST_CASE("separable part: comparators tao 2, 4, 6, implicit midpoint, gauss with 1, 2, 3, 4 stages") {
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
        // Gauss with 5 to 8 stages reaches round-off before its asymptotic regime (test_core_convergence.cpp).
        if (scheme.name == "gauss" && order.value() > 8) continue;
        CAPTURE(order.to_string());
        CHECK(std::find(covered.begin(), covered.end(), order) != covered.end());
      }
  }
}

TEST_CASE("separable part in the VVT form with K and U: the reference solves the model's H") {
  const testing::SwappedVariableMass2D model;
  const double z[] = {0.4, -0.9, 0.7, -0.3};
  EnergyEvaluator energy(HamiltonianForm::VVT);
  CHECK(energy.evaluate_one(model, PhaseSpaceBatch::single(std::span(z, 2), std::span(z + 2, 2))) ==
        doctest::Approx(model.hamiltonian(z)).epsilon(1e-14));
  std::vector<double> dxdt(4);
  swapped_rhs(std::vector<double>(z, z + 4), dxdt);
  const std::vector<double> point(z, z + 4);
  const auto h = [&](const std::vector<double>& w) { return std::vector<double>{model.hamiltonian(w.data())}; };
  for (std::size_t k = 0; k < 4; ++k) {
    const double dh = testing::central_difference_along(h, point, k, 1e-5)[0];
    CHECK((k < 2 ? -dxdt[k + 2] : dxdt[k - 2]) == doctest::Approx(dh).epsilon(1e-8));
  }
}

TEST_CASE(
    "separable part in the VVT form with K and U: basic, triplet and MPE converge with their orders up to 10/3 and 4") {
  for (const Study& study : vvt_cases()) {
    CAPTURE(study.spec.scheme);
    CAPTURE(Integrator(study.spec).describe().order.to_string());
    CHECK(
        std::abs(measured_order(study, testing::SwappedVariableMass2D{}, swapped_start, swapped_end(), swapped_t_end) -
                 study.nominal) < 0.1);
  }
}

}  // namespace test_separable_convergence
