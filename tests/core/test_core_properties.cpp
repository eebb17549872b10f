// Structural properties of the integrators: time reversibility, symplecticity (one-step Jacobian), batch
// consistency, first-same-as-last evaluation counts, energy, and the VVT form against an independent reference.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "support/convergence.hpp"
#include "support/models.hpp"
#include "support/nan_aware.hpp"
#include "support/phase_space_jacobian.hpp"

namespace test_core_properties {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;

namespace {

PhaseSpaceBatch state(std::vector<double> q, std::vector<double> p) { return PhaseSpaceBatch::single(q, p); }

double max_difference(const PhaseSpaceBatch& a, const PhaseSpaceBatch& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    d = testing::max_or_nan(d, testing::max_or_nan(std::abs(a.q()[i] - b.q()[i]), std::abs(a.p()[i] - b.p()[i])));
  return d;
}

// max |J^T Omega J - Omega| of the one-step Jacobian J = d(q', p')/d(q, p) by central differences
// (support/finite_difference.hpp): zero for a symplectic map up to the differencing error (~1e-9 here); NaN when
// the step is not finite.
template <class M>
double symplecticity_defect(const M& model, const IntegratorSpec& spec, const PhaseSpaceBatch& x0, double dt) {
  return testing::symplecticity_defect(
      testing::jacobian_by_differences(testing::integrator_map(model, spec, dt), testing::phase_point(x0), 1e-6));
}

const std::array<HamiltonianForm, 2> forms{HamiltonianForm::TTV, HamiltonianForm::VVT};
const double t2_default = ChinCoefficients::default_t2();

}  // namespace

TEST_CASE("the coefficients of eq. (expalg)") {
  const auto c = ChinCoefficients::from_t2(-2.0);
  CHECK(c.t1 == 2.0);
  CHECK(c.v1 == 0.25);
  CHECK(c.v2 == -0.125);
  CHECK(c.v0 == -0.25);
  // e_T = e_V = 0 (eq. tvzero): the drifts and the kicks each sum to zero.
  CHECK(2 * c.t1 + 2 * c.t2 == 0.0);
  CHECK(c.v0 + 2 * c.v1 + 2 * c.v2 == 0.0);
  CHECK(ChinCoefficients::default_t2() == -1.8171205928321397);  // exactly: one number on every compiler
}

TEST_CASE("a step of dt followed by one of -dt returns to the start (basic and triplet, both forms)") {
  for (const char* scheme : {"basic", "triplet"})
    for (const Fraction order : {Fraction(2, 3), Fraction(4, 3), Fraction(2)})
      for (const auto form : forms) {
        if (std::string(scheme) == "basic" && order != Fraction(2, 3)) continue;
        CAPTURE(scheme);
        CAPTURE(order.to_string());
        CAPTURE(static_cast<int>(form));
        Integrator integrator(IntegratorSpec{scheme, ChinOptions{order, t2_default}, form});
        const auto start1 = state({1.3}, {0.4});
        auto x1 = start1;
        integrator.step(Paper1D{}, x1, 0.01);
        CHECK(max_difference(x1, start1) > 1e-4);  // it did move
        integrator.step(Paper1D{}, x1, -0.01);
        CHECK(max_difference(x1, start1) < 1e-12);
        const auto start2 = state({0.7, -0.3}, {0.2, 0.5});
        auto x2 = start2;
        integrator.step(Coupled2D{}, x2, 0.02);
        integrator.step(Coupled2D{}, x2, -0.02);
        CHECK(max_difference(x2, start2) < 1e-12);
      }
}

TEST_CASE("the one-step map is symplectic for basic and triplet, and MPE is not") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    for (const Fraction order : {Fraction(2, 3), Fraction(4, 3), Fraction(2)}) {
      CAPTURE(order.to_string());
      const IntegratorSpec triplet{"triplet", ChinOptions{order, t2_default}, form};
      // dt = 0.02: at 0.05 the order-2 triplet's largest basic step (6.4 dt) throws paper1d from
      // (1.2, 0.5) to infinity in one step (its drift is cubic in p).
      CHECK(symplecticity_defect(Paper1D{}, triplet, state({1.2}, {0.5}), 0.02) < 1e-8);
      CHECK(symplecticity_defect(Coupled2D{}, triplet, state({0.6, -0.4}, {0.3, 0.2}), 0.02) < 1e-8);
    }
    const IntegratorSpec basic{"basic", ChinOptions{Fraction(2, 3), -2.5}, form};
    CHECK(symplecticity_defect(Paper1D{}, basic, state({1.2}, {0.5}), 0.1) < 1e-8);
    CHECK(symplecticity_defect(Coupled2D{}, basic, state({0.6, -0.4}, {0.3, 0.2}), 0.1) < 1e-8);
    // The same measurement on MPE finds a defect far above the finite-difference noise (~1e-10) and the 1e-8 tolerance.
    const IntegratorSpec mpe{"mpe", ChinOptions{Fraction(4, 3), t2_default}, form};
    CHECK(symplecticity_defect(Paper1D{}, mpe, state({1.2}, {0.5}), 0.1) > 1e-6);
    CHECK(symplecticity_defect(Coupled2D{}, mpe, state({0.6, -0.4}, {0.3, 0.2}), 0.1) > 1e-6);
  }
}

TEST_CASE("stepping a batch equals stepping each state alone, bit for bit") {
  for (const char* scheme : {"basic", "triplet", "mpe"}) {
    const std::string scheme_name = scheme;
    CAPTURE(scheme_name);
    const IntegratorSpec spec{scheme, ChinOptions{Fraction(std::string(scheme) == "basic" ? 2 : 4, 3)}};
    PhaseSpaceBatch batch(2, 3);
    const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
    std::copy(std::begin(qs), std::end(qs), batch.q().begin());
    std::copy(std::begin(ps), std::end(ps), batch.p().begin());
    Integrator together(spec);
    for (int s = 0; s < 10; ++s) together.step(Coupled2D{}, batch, 0.01);
    for (std::size_t b = 0; b < 3; ++b) {
      auto x = state({qs[2 * b], qs[2 * b + 1]}, {ps[2 * b], ps[2 * b + 1]});
      Integrator alone(spec);
      for (int s = 0; s < 10; ++s) alone.step(Coupled2D{}, x, 0.01);
      CHECK(x.q()[0] == batch.q(b)[0]);
      CHECK(x.q()[1] == batch.q(b)[1]);
      CHECK(x.p()[0] == batch.p(b)[0]);
      CHECK(x.p()[1] == batch.p(b)[1]);
    }
  }
}

TEST_CASE("first-same-as-last: 4 grad T + 4 grad V per basic step, plus one at the start") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    const bool ttv = form == HamiltonianForm::TTV;
    ChinBasicStep basic(form);
    auto x = state({1.0}, {0.2});
    // Steps of different sizes, including a negative one: the cached gradient depends on the point, not on dt.
    const double dts[] = {0.01, 0.02, -0.005, 0.013, 0.01};
    for (double dt : dts) basic.step(Paper1D{}, x, dt);
    const std::uint64_t outer = 4 * 5 + 1, inner = 4 * 5;
    CHECK(basic.evaluations().grad_V == (ttv ? outer : inner));
    CHECK(basic.evaluations().grad_T == (ttv ? inner : outer));

    // A state changed from outside invalidates the cached gradient: one more evaluation, never a stale one.
    x.q()[0] += 0.1;
    x.p()[0] += 0.1;
    basic.step(Paper1D{}, x, 0.01);
    CHECK(basic.evaluations().grad_V + basic.evaluations().grad_T == 2 * 4 * 6 + 2);
  }
  // Triplet of order 2 (9 basic steps per step) on a batch of 3 states: counts are per state.
  TripletComposition<> triplet(ChinBasicStep(), 2);
  PhaseSpaceBatch batch(1, 3);
  batch.q()[0] = 0.5, batch.q()[1] = 1.0, batch.q()[2] = 1.5;
  for (int s = 0; s < 7; ++s) triplet.step(Paper1D{}, batch, 0.01);
  CHECK(triplet.describe().basic_steps_per_step == 9);
  CHECK(triplet.evaluations().grad_T == 3 * 4 * 9 * 7);
  CHECK(triplet.evaluations().grad_V == 3 * (4 * 9 * 7 + 1));
  // MPE with m = 3 terms runs 1 + 2 + 3 basic steps per step from one shared starting gradient; the combined
  // point is new, so each step evaluates one starting gradient.
  MultiProductExpansion<> mpe(ChinBasicStep(), 3);
  auto y = state({1.0}, {0.0});
  for (int s = 0; s < 5; ++s) mpe.step(Paper1D{}, y, 0.01);
  CHECK(mpe.describe().basic_steps_per_step == 6);
  CHECK(mpe.evaluations().grad_T == 4 * 6 * 5);
  CHECK(mpe.evaluations().grad_V == (4 * 6 + 1) * 5);
}

TEST_CASE("first-same-as-last: a batch cut to its first states keeps its cached gradient (keep_cache_prefix)") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    PhaseSpaceBatch batch(2, 3);
    const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
    std::copy(std::begin(qs), std::end(qs), batch.q().begin());
    std::copy(std::begin(ps), std::end(ps), batch.p().begin());
    ChinBasicStep cut(form);
    cut.step(Coupled2D{}, batch, 0.01);
    const double* storage = batch.q().data();
    batch.resize(2);
    CHECK(batch.count() == 2);
    CHECK(batch.q().data() == storage);  // the first states stay where they were
    auto alone = PhaseSpaceBatch::single(batch.q(1), batch.p(1));
    ChinBasicStep fresh(form);
    fresh.step(Coupled2D{}, alone, 0.02);
    const auto before = cut.evaluations();
    cut.keep_cache_prefix(batch.size());
    cut.step(Coupled2D{}, batch, 0.02);
    // 4 + 4 per state of the 2 left and no new starting gradient; state 1 as stepped alone, bit for bit.
    CHECK(cut.evaluations().grad_T + cut.evaluations().grad_V == before.grad_T + before.grad_V + 2 * 8);
    CHECK(std::ranges::equal(batch.q(1), alone.q()));
    CHECK(std::ranges::equal(batch.p(1), alone.p()));
    batch.resize(3);
    CHECK(batch.q().data() == storage);  // growing back within the storage does not move it
    CHECK(batch.q(2)[0] == 0.0);
    CHECK(batch.p(2)[1] == 0.0);
  }
}

// Paper1D whose gradient evaluation number `fail_at` (counting both gradients from 1) throws ModelError after
// writing garbage into its output, as a failing plugin may leave it.
struct FailingOnce {
  mutable int calls = 0;
  int fail_at = 0;
  std::size_t dimension() const { return 1; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    fail_if_due(out, count);
    Paper1D{}.grad_T(p, out, count);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    fail_if_due(out, count);
    Paper1D{}.grad_V(q, out, count);
  }
  void fail_if_due(std::span<double> out, std::size_t count) const {
    if (++calls != fail_at) return;
    for (std::size_t b = 0; b < count; ++b) out[b] = 1e6;
    throw ModelError("failing on purpose");
  }
};

TEST_CASE("first-same-as-last: a step the model fails partway leaves no stale gradient behind") {
  // Evaluation 1 is the starting gradient, 2..9 the first step; the second step fails at each of its 8
  // evaluations in turn. The states go back to where they were (as the host's retry does) and the same stepper
  // steps again: it must give what a stepper that never failed gives, bit for bit.
  for (const auto form : forms) {
    for (int failing = 10; failing <= 17; ++failing) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(failing);
      FailingOnce model{0, failing};
      ChinBasicStep stepper(form), reference(form);
      auto x = state({0.7}, {0.3});
      auto y = x;
      stepper.step(model, x, 0.01);
      reference.step(Paper1D{}, y, 0.01);
      const auto before = x;
      CHECK_THROWS_AS(stepper.step(model, x, 0.01), ModelError);
      x = before;
      stepper.step(model, x, 0.01);
      reference.step(Paper1D{}, y, 0.01);
      CHECK(x == y);
    }
  }
}

TEST_CASE("step_n: n steps in one call give n calls of step bit for bit, with the same evaluation counts") {
  for (const auto form : forms) {
    for (std::size_t count : {std::size_t{1}, std::size_t{5}}) {  // one number takes the scalar flow
      CAPTURE(static_cast<int>(form));
      CAPTURE(count);
      PhaseSpaceBatch x(1, count);
      for (std::size_t b = 0; b < count; ++b) x.q()[b] = 0.3 + 0.2 * static_cast<double>(b), x.p()[b] = 0.1;
      auto y = x;
      ChinBasicStep together(form), one_by_one(form);
      together.step_n(Paper1D{}, x, 0.01, 7);
      together.step_n(Paper1D{}, x, -0.02, 3);  // the point carries over from one call to the next
      together.step_n(Paper1D{}, x, 0.01, 0);   // nothing
      for (int s = 0; s < 7; ++s) one_by_one.step(Paper1D{}, y, 0.01);
      for (int s = 0; s < 3; ++s) one_by_one.step(Paper1D{}, y, -0.02);
      CHECK(x == y);
      CHECK(together.evaluations() == one_by_one.evaluations());
      CHECK(together.evaluations().grad_T + together.evaluations().grad_V == count * (8 * 10 + 1));
    }
  }
  for (const char* scheme : {"basic", "triplet", "mpe"}) {
    const std::string scheme_name = scheme;
    CAPTURE(scheme_name);
    const IntegratorSpec spec{scheme, ChinOptions{Fraction(std::string(scheme) == "basic" ? 2 : 4, 3)}};
    auto x = state({0.5, -0.2}, {0.1, 0.3});
    auto y = x;
    Integrator together(spec), one_by_one(spec);
    together.step_n(Coupled2D{}, x, 0.01, 6);
    for (int s = 0; s < 6; ++s) one_by_one.step(Coupled2D{}, y, 0.01);
    CHECK(x == y);
    CHECK(together.evaluations() == one_by_one.evaluations());
  }
}

TEST_CASE("step_n: a run the model fails partway leaves no stale gradient behind") {
  // Evaluation 1 is the starting gradient, 2..9 the first step, 10..17 the second, 18..25 the third: a run of three
  // steps fails at each evaluation of its second and third step in turn. The states go back to where the run began
  // and the same stepper runs again: it must give what a stepper that never failed gives, bit for bit.
  for (const auto form : forms) {
    for (int failing = 10; failing <= 25; ++failing) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(failing);
      FailingOnce model{0, failing};
      ChinBasicStep stepper(form), reference(form);
      auto x = state({0.7}, {0.3});
      auto y = x;
      const auto before = x;
      CHECK_THROWS_AS(stepper.step_n(model, x, 0.01, 3), ModelError);
      x = before;
      stepper.step_n(model, x, 0.01, 3);
      reference.step_n(Paper1D{}, y, 0.01, 3);
      CHECK(x == y);
    }
  }
}

TEST_CASE(
    "a batch's q and p start on a cache line from 32 numbers on, also when copied, moved or made from one "
    "state") {
  const auto on_line = [](std::span<const double> values) {
    return reinterpret_cast<std::uintptr_t>(values.data()) % cache_line_size == 0;
  };
  for (std::size_t count : {std::size_t{16}, std::size_t{17}, std::size_t{256}}) {
    CAPTURE(count);
    const PhaseSpaceBatch x(2, count);
    const PhaseSpaceBatch copy = x;
    PhaseSpaceBatch moved = PhaseSpaceBatch(x);
    for (const PhaseSpaceBatch* batch : std::array<const PhaseSpaceBatch*, 3>{&x, &copy, &moved}) {
      CHECK(on_line(batch->q()));
      CHECK(on_line(batch->p()));
    }
  }
  const std::vector<double> q(40, 0.5), p(40, 0.25);
  const auto single = PhaseSpaceBatch::single(q, p);
  CHECK(on_line(single.q()));
  CHECK(on_line(single.p()));
  // Smaller arrays come from the ordinary heap; what matters there is that a vector can still free them.
  AlignedDoubles small(3, 1.0), large(64, 1.0);
  small = large;
  large.resize(2);
  large.shrink_to_fit();
  CHECK(small.size() == 64);
  CHECK(large.size() == 2);
}

TEST_CASE("the MPE weights of eqs. (mpe43) and (mpe63)") {
  const double n = 2.0 / 3.0, a = 1, b = std::pow(2.0, n), c = std::pow(3.0, n);
  const auto w2 = MultiProductExpansion<>::weights_for(2);
  CHECK(w2[0] == doctest::Approx(a / (a - b)));
  CHECK(w2[1] == doctest::Approx(b / (b - a)));
  const auto w3 = MultiProductExpansion<>::weights_for(3);
  CHECK(w3[0] == doctest::Approx(a * a / ((a - b) * (a - c))));
  CHECK(w3[1] == doctest::Approx(b * b / ((b - a) * (b - c))));
  CHECK(w3[2] == doctest::Approx(c * c / ((c - a) * (c - b))));
  for (int m = 1; m <= 8; ++m) {
    double sum = 0;
    for (double w : MultiProductExpansion<>::weights_for(m)) sum += w;
    CHECK(sum == doctest::Approx(1.0).epsilon(1e-10));
  }
}

TEST_CASE("energy of the solved Hamiltonian in both forms") {
  const auto x = state({1.3}, {-0.7});
  EnergyEvaluator ttv(HamiltonianForm::TTV), vvt(HamiltonianForm::VVT);
  CHECK(ttv.evaluate_one(Paper1D{}, x) == doctest::Approx(Paper1D::H_TTV(1.3, -0.7)).epsilon(1e-15));
  CHECK(vvt.evaluate_one(Paper1D{}, x) == doctest::Approx(Paper1D::H_VVT(1.3, -0.7)).epsilon(1e-15));
  // In 2D the energy is the quadratic form grad T . Hess V grad T, checked here against a hand computation.
  const auto y = state({0.5, -0.2}, {0.3, 0.1});
  std::array<double, 2> g{};
  std::array<double, 4> h{};
  Coupled2D{}.grad_T(y.p(), g, 1);
  Coupled2D{}.hessian_V(y.q(), h, 1);
  const double expected = g[0] * (h[0] * g[0] + h[1] * g[1]) + g[1] * (h[2] * g[0] + h[3] * g[1]);
  CHECK(ttv.evaluate_one(Coupled2D{}, y) == doctest::Approx(expected).epsilon(1e-15));
}

namespace {
// A chain of dimension n: T = |p|^2/2, V = sum q_i^4/4 + sum q_i q_(i+1) / 2, so H_TTV = sum 3 q_i^2 p_i^2 +
// sum p_i p_(i+1). Large enough that its Hessians do not fit in one EnergyEvaluator call for a few states.
struct Chain {
  std::size_t n;
  std::size_t dimension() const { return n; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < count * n; ++i) out[i] = p[i];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t i = 0; i < count * n; ++i) out[i] = q[i] * q[i] * q[i];
  }
  void hessian_T(std::span<const double>, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b)
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) out[(b * n + i) * n + j] = i == j ? 1.0 : 0.0;
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b)
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j)
          out[(b * n + i) * n + j] = i == j                       ? 3.0 * q[b * n + i] * q[b * n + i]
                                     : (i + 1 == j || j + 1 == i) ? 0.5
                                                                  : 0.0;
  }
};
}  // namespace

TEST_CASE("energy of many large states: evaluated a few at a time, each state's H as when evaluated alone") {
  const Chain chain{400};  // 160000 Hessian entries a state: the evaluator takes 6 states per call
  const std::size_t count = 13;
  PhaseSpaceBatch x(chain.n, count);
  for (std::size_t i = 0; i < chain.n * count; ++i) {
    x.q()[i] = std::sin(0.37 * static_cast<double>(i));
    x.p()[i] = std::cos(0.11 * static_cast<double>(i));
  }
  EnergyEvaluator energy(HamiltonianForm::TTV);
  std::vector<double> energies(count);
  energy.evaluate(chain, x, energies);
  for (std::size_t b = 0; b < count; ++b) {
    CAPTURE(b);
    PhaseSpaceBatch one(chain.n, 1);
    std::copy_n(x.q().begin() + static_cast<std::ptrdiff_t>(b * chain.n), chain.n, one.q().begin());
    std::copy_n(x.p().begin() + static_cast<std::ptrdiff_t>(b * chain.n), chain.n, one.p().begin());
    CHECK(energies[b] == energy.evaluate_one(chain, one));
    double expected = 0.0;
    for (std::size_t i = 0; i < chain.n; ++i) {
      const double q = one.q()[i], p = one.p()[i];
      expected += 3.0 * q * q * p * p + (i + 1 < chain.n ? p * one.p()[i + 1] : 0.0);
    }
    CHECK(energies[b] == doctest::Approx(expected).epsilon(1e-12));
  }
}

TEST_CASE("the VVT form converges to the exact flow of H_VVT = (q + q^3/3)^2 p") {
  // Paper1D in VVT form solves H_VVT = V'(q)^2 T''(p) = (q + q^3/3)^2 p. Reference: Hamilton's equations
  // dq/dt = (q + q^3/3)^2, dp/dt = -2 (q + q^3/3)(1 + q^2) p integrated by Runge-Kutta-Fehlberg 7(8).
  auto rhs = [](const std::vector<double>& s, std::vector<double>& d) {
    const double q = s[0], p = s[1], w = q + q * q * q / 3.0;
    d[0] = w * w;
    d[1] = -2.0 * w * (1.0 + q * q) * p;
  };
  const double t_end = 0.5;
  const auto reference = nonsep::reference::hamiltonian_flow(rhs, {0.5, 0.5}, t_end);
  for (const auto& [order, expected, first] :
       {std::tuple{Fraction(2, 3), 2.0 / 3, 512}, std::tuple{Fraction(4, 3), 4.0 / 3, 256}}) {
    const std::string order_name = order.to_string();  // clang 14 cannot capture a structured binding
    CAPTURE(order_name);
    std::vector<double> dts, errors;
    for (int steps = first; steps <= 8 * first; steps *= 2) {
      Integrator integrator(IntegratorSpec{"triplet", ChinOptions{order, t2_default}, HamiltonianForm::VVT});
      auto x = state({0.5}, {0.5});
      for (int s = 0; s < steps; ++s) integrator.step(Paper1D{}, x, t_end / steps);
      dts.push_back(t_end / steps);
      errors.push_back(std::hypot(x.q()[0] - reference[0], x.p()[0] - reference[1]));
    }
    MESSAGE("VVT " << order.to_string() << ": error " << errors.back() << " at dt " << dts.back());
    CHECK(errors.back() < errors.front());
    CHECK(std::abs(nonsep::testing::fitted_exponent(dts, errors) - expected) < 0.1);
  }
}

TEST_CASE("a basic step with one dt per state gives each state what a step of its dt alone gives, bit for bit") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
    const std::vector<double> dts{0.01, -0.003, 0.02 / 3.0};
    PhaseSpaceBatch batch(2, 3);
    std::copy(std::begin(qs), std::end(qs), batch.q().begin());
    std::copy(std::begin(ps), std::end(ps), batch.p().begin());
    ChinBasicStep together(form, -2.0);
    for (int s = 0; s < 4; ++s) together.step(Coupled2D{}, batch, dts);
    std::uint64_t evaluations = 0;
    for (std::size_t b = 0; b < 3; ++b) {
      auto x = state({qs[2 * b], qs[2 * b + 1]}, {ps[2 * b], ps[2 * b + 1]});
      ChinBasicStep alone(form, -2.0);
      for (int s = 0; s < 4; ++s) alone.step(Coupled2D{}, x, dts[b]);
      CHECK(x == PhaseSpaceBatch::single(batch.q(b), batch.p(b)));
      evaluations += alone.evaluations().grad_T + alone.evaluations().grad_V;
    }
    CHECK(together.evaluations().grad_T + together.evaluations().grad_V == evaluations);
    CHECK_THROWS_AS(together.step(Coupled2D{}, batch, std::vector<double>{0.01, 0.01}), InvalidArgument);
    CHECK_THROWS_AS(together.step(Coupled2D{}, batch, std::vector<double>{0.01, 0.0, 0.01}), InvalidArgument);
  }
}

namespace {
// Coupled2D, counting the calls into it (each call is one crossing of a plugin boundary in the host).
struct CountingCoupled2D : Coupled2D {
  mutable std::uint64_t calls = 0;
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    ++calls;
    Coupled2D::grad_T(p, out, count);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    ++calls;
    Coupled2D::grad_V(q, out, count);
  }
};
}  // namespace

TEST_CASE("MPE: the terms batched give the term-by-term numbers and evaluation counts bit for bit, in 8m calls") {
  for (const auto form : forms)
    for (int m = 1; m <= 6; ++m) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(m);
      PhaseSpaceBatch batched(2, 3);
      const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
      std::copy(std::begin(qs), std::end(qs), batched.q().begin());
      std::copy(std::begin(ps), std::end(ps), batched.p().begin());
      PhaseSpaceBatch sequential = batched;
      MultiProductExpansion<> together(ChinBasicStep(form), m), one_by_one(ChinBasicStep(form), m);
      const CountingCoupled2D model_together, model_one_by_one;
      for (double dt : {0.01, 0.01, -0.004, 0.02}) {
        together.step(model_together, batched, dt);
        one_by_one.step_term_by_term(model_one_by_one, sequential, dt);
        CHECK(batched == sequential);
      }
      CHECK(together.evaluations().grad_T == one_by_one.evaluations().grad_T);
      CHECK(together.evaluations().grad_V == one_by_one.evaluations().grad_V);
      // Per step: 8 calls per round (m rounds) plus one for the new starting point; term by term 8 per basic
      // step, m(m+1)/2 of them.
      const auto steps = 4u, rounds = static_cast<unsigned>(m), basic = static_cast<unsigned>(m * (m + 1) / 2);
      if (m == 1) {  // the basic step itself: first-same-as-last across steps
        CHECK(model_together.calls == 8 * steps + 1);
        CHECK(model_one_by_one.calls == 8 * steps + 1);
      } else {
        CHECK(model_together.calls == steps * (8 * rounds + 1));
        CHECK(model_one_by_one.calls == steps * (8 * basic + 1));
      }
    }
}

}  // namespace test_core_properties
