// Models given by H(q, p) itself (model.hpp, ModelWithGeneralHamiltonian): the schemes that integrate H
// (Gauss-Legendre, Tao's extended phase space), their tangent maps and the energy serve them through the one interface
// of hamiltonian_gradient.hpp. A charged particle in a uniform magnetic field with an isotropic harmonic potential is a
// linear system with an exact solution, which gauss 3 stages must follow to 1e-12 over 100 gyrations. A product-form
// model and the same Hamiltonian written as one H (the SDK's HamiltonianAdapter) give the same numbers.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "henon_heiles/henon_heiles.hpp"
#include "magnetic_bottle/magnetic_bottle.hpp"
#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/core/tangent/tangent_gauss_legendre.hpp"
#include "nonsep/derivative_checker.hpp"
#include "paper1d/paper1d.hpp"

namespace test_general_hamiltonian {

using namespace nonsep;

namespace {

// H = ((p1 + B q2/2)^2 + (p2 - B q1/2)^2)/2 + w^2 (q1^2 + q2^2)/2: unit mass and charge, field B along the third axis
// in the symmetric gauge A = B (-q2, q1)/2, and an isotropic harmonic potential of frequency w. Written by hand: the
// velocity v = p - A, dH/dp = v, dH/dq = (-B v2/2 + w^2 q1, B v1/2 + w^2 q2); the Hessian is constant.
struct UniformField {
  double B = 1.0, w = 0.5;
  std::size_t dimension() const { return 2; }
  void velocity(const double* q, const double* p, double* v) const {
    v[0] = p[0] + B * q[1] / 2;
    v[1] = p[1] - B * q[0] / 2;
  }
  void value_H(std::span<const double> q, std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      double v[2];
      velocity(&q[2 * b], &p[2 * b], v);
      out[b] = (v[0] * v[0] + v[1] * v[1]) / 2 + w * w * (q[2 * b] * q[2 * b] + q[2 * b + 1] * q[2 * b + 1]) / 2;
    }
  }
  void grad_H(std::span<const double> q, std::span<const double> p, std::span<double> dq, std::span<double> dp,
              std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) {
      double v[2];
      velocity(&q[2 * b], &p[2 * b], v);
      dp[2 * b] = v[0];
      dp[2 * b + 1] = v[1];
      dq[2 * b] = -B * v[1] / 2 + w * w * q[2 * b];
      dq[2 * b + 1] = B * v[0] / 2 + w * w * q[2 * b + 1];
    }
  }
  // grad H is linear: its directional derivative is grad H of the direction with the same formulas.
  void hvp_H(HamiltonianForm, std::span<const double>, std::span<const double>, std::span<const double> dq,
             std::span<const double> dp, std::span<double> out_q, std::span<double> out_p, std::size_t count) const {
    grad_H(dq, dp, out_q, out_p, count);
  }
};
static_assert(ModelWithGeneralHamiltonian<UniformField> && HamiltonianModel<UniformField>);
static_assert(ModelWithHamiltonianHessian<UniformField> && !Model<UniformField>);

// The exact state at time t from (q, p): with u = q1 + i q2, u'' = -i B u' - w^2 u, so u = a e^{i k1 t} + c e^{i k2 t}
// with k^2 + B k - w^2 = 0; p = v + A.
std::vector<double> exact_state(const UniformField& m, const double* q, const double* p, double t) {
  using C = std::complex<double>;
  const C i(0, 1);
  const double root = std::sqrt(m.B * m.B + 4 * m.w * m.w);
  const double k1 = (-m.B + root) / 2, k2 = (-m.B - root) / 2;
  double v[2];
  m.velocity(q, p, v);
  const C u0(q[0], q[1]), du0(v[0], v[1]);
  // a + c = u0, i k1 a + i k2 c = du0
  const C a = (du0 - i * k2 * u0) / (i * (k1 - k2)), c = u0 - a;
  const C u = a * std::exp(i * k1 * t) + c * std::exp(i * k2 * t);
  const C du = i * k1 * a * std::exp(i * k1 * t) + i * k2 * c * std::exp(i * k2 * t);
  return {u.real(), u.imag(), du.real() - m.B * u.imag() / 2, du.imag() + m.B * u.real() / 2};
}

PhaseSpaceBatch two_states(const double* q, const double* p) {
  PhaseSpaceBatch x(2, 2);
  std::copy(q, q + 4, x.q().begin());
  std::copy(p, p + 4, x.p().begin());
  return x;
}

}  // namespace

TEST_CASE("general H: gauss 3 stages follows a charged particle in a uniform field to 1e-12 over 100 gyrations") {
  const UniformField model;
  const double q0[] = {1.0, 0.0, 0.3, -0.4}, p0[] = {0.0, 0.8, -0.5, 0.2};
  auto x = two_states(q0, p0);
  GaussLegendre gauss(HamiltonianForm::TTV, 6);
  const double period = 2 * M_PI / model.B, t_end = 100 * period;
  const int steps = 40000;
  const double dt = t_end / steps;
  for (int s = 0; s < steps; ++s) gauss.step(model, x, dt);
  double error = 0.0;
  for (std::size_t b = 0; b < 2; ++b) {
    const auto exact = exact_state(model, q0 + 2 * b, p0 + 2 * b, t_end);
    for (std::size_t k = 0; k < 2; ++k) {
      error = std::max(error, std::abs(x.q()[2 * b + k] - exact[k]));
      error = std::max(error, std::abs(x.p()[2 * b + k] - exact[2 + k]));
    }
  }
  MESSAGE("gauss 3 stages, dt = " << dt << ", 100 gyrations: largest error " << error);
  CHECK(error < 1e-12);
  CHECK(gauss.evaluations().grad_H > 0);
  // The energy of a general model is its value_H.
  EnergyEvaluator energy(HamiltonianForm::TTV);
  std::vector<double> h(2), h0(2);
  energy.evaluate(model, x, h);
  const auto start = two_states(q0, p0);
  energy.evaluate(model, start, h0);
  CHECK(h[0] == doctest::Approx(h0[0]).epsilon(1e-13));
  CHECK(h[1] == doctest::Approx(h0[1]).epsilon(1e-13));
}

TEST_CASE("general H: Tao's scheme and the tangent map of gauss take a model given by H") {
  const UniformField model;
  const double q0[] = {1.0, 0.0}, p0[] = {0.0, 0.8};
  SUBCASE("tao order 4 converges to the exact state") {
    auto x = PhaseSpaceBatch::single(q0, p0);
    TaoExtendedPhaseSpace tao(HamiltonianForm::TTV, 4);
    const double t_end = 2 * M_PI;
    for (int s = 0; s < 1000; ++s) tao.step(model, x, t_end / 1000);
    const auto exact = exact_state(model, q0, p0, t_end);
    CHECK(std::abs(x.q()[0] - exact[0]) < 1e-8);
    CHECK(std::abs(x.p()[1] - exact[3]) < 1e-8);
  }
  SUBCASE("the tangent map of a linear flow is the flow itself") {
    auto x = PhaseSpaceBatch::single(q0, p0);
    const double dq[] = {0.3, -0.1}, dp[] = {0.2, 0.5};
    auto tangent = PhaseSpaceBatch::single(dq, dp);
    TangentGaussLegendre map(GaussLegendre(HamiltonianForm::TTV, 6));
    for (int s = 0; s < 100; ++s) map.step(model, x, tangent, 0.01);
    const auto exact = exact_state(model, dq, dp, 1.0);
    CHECK(tangent.q()[0] == doctest::Approx(exact[0]).epsilon(1e-12));
    CHECK(tangent.q()[1] == doctest::Approx(exact[1]).epsilon(1e-12));
    CHECK(tangent.p()[0] == doctest::Approx(exact[2]).epsilon(1e-12));
    CHECK(tangent.p()[1] == doctest::Approx(exact[3]).epsilon(1e-12));
  }
}

namespace {

// Henon-Heiles as K(p) + U(q) with a zero product term (T = V = 0): the separable form the product-form models have.
struct HenonHeilesSeparable {
  static constexpr std::size_t dimension = 2;
  template <class S>
  S T(sdk::Vector<S> p) const {
    return 0.0 * p[0];
  }
  template <class S>
  S V(sdk::Vector<S> q) const {
    return 0.0 * q[0];
  }
  template <class S>
  S K(sdk::Vector<S> p) const {
    return (p[0] * p[0] + p[1] * p[1]) / 2.0;
  }
  template <class S>
  S U(sdk::Vector<S> q) const {
    return (q[0] * q[0] + q[1] * q[1]) / 2.0 + (q[0] * q[0] * q[1] - sdk::cube(q[1]) / 3.0);
  }
};

// The paper's 1D model written as one H: H_TTV = T'(p)^2 V''(q) = (1 + p^2/2)^2 (1 + q^2) (plugins/paper1d).
struct Paper1DAsH {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S H(sdk::Vector<S> q, sdk::Vector<S> p) const {
    const S g = 1.0 + p[0] * p[0] / 2.0;
    return g * g * (1.0 + q[0] * q[0]);
  }
};

// Steps x by gauss 3 stages with one tangent vector and the largest Lyapunov exponent, `steps` steps of dt.
template <class M>
std::pair<PhaseSpaceBatch, double> gauss3_with_exponent(const M& model, PhaseSpaceBatch x, double dt, int steps) {
  TangentGaussLegendre map(GaussLegendre(HamiltonianForm::TTV, 6));
  const std::size_t n = x.dimension();
  PhaseSpaceBatch tangent(n, 1);
  for (std::size_t i = 0; i < n; ++i) tangent.q()[i] = tangent.p()[i] = 1.0;
  LyapunovExponents lyapunov(1, 10);
  std::array<LyapunovRecord, 1> record{};
  lyapunov.start(tangent, record);
  for (int s = 0; s < steps; ++s) {
    map.step(model, x, tangent, dt);
    lyapunov.after_step(tangent, record, dt);
  }
  return {x, record[0].exponent(0)};
}

double largest_difference(const PhaseSpaceBatch& a, const PhaseSpaceBatch& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < a.q().size(); ++i)
    d = std::max({d, std::abs(a.q()[i] - b.q()[i]), std::abs(a.p()[i] - b.p()[i])});
  return d;
}

}  // namespace

TEST_CASE("general H: Henon-Heiles as one H equals its K + U form with gauss 3 stages, Lyapunov exponent too") {
  const sdk::HamiltonianAdapter<HenonHeiles> general;
  const sdk::ModelAdapter<HenonHeilesSeparable> separable;
  static_assert(ModelWithGeneralHamiltonian<decltype(general)> && ModelWithSeparablePart<decltype(separable)>);
  // A regular and a chaotic start at E = 1/8 (Henon and Heiles' energy of mixed phase space).
  for (const auto& [q0, p0] : {std::pair{std::array{0.0, 0.1}, std::array{0.49, 0.0}},
                               std::pair{std::array{0.0, -0.2}, std::array{0.4, 0.2}}}) {
    const auto start = PhaseSpaceBatch::single(q0, p0);
    const auto [x_general, exponent_general] = gauss3_with_exponent(general, start, 0.01, 10000);
    const auto [x_separable, exponent_separable] = gauss3_with_exponent(separable, start, 0.01, 10000);
    const double difference = largest_difference(x_general, x_separable);
    MESSAGE("q0 = (" << q0[0] << ", " << q0[1] << "): state difference at t = 100 " << difference
                     << ", Lyapunov exponents " << exponent_general << " and " << exponent_separable);
    CHECK(difference <= 1e-13);
    CHECK(std::abs(exponent_general - exponent_separable) <= 1e-13);
  }
}

TEST_CASE("general H: paper1d written as one H equals the product-form paper1d with gauss 3 stages to round-off") {
  const sdk::HamiltonianAdapter<Paper1DAsH> general;
  const sdk::ModelAdapter<Paper1D> product;
  const double q0[] = {2.0}, p0[] = {0.0};
  auto a = PhaseSpaceBatch::single(q0, p0), b = a;
  GaussLegendre gauss_a(HamiltonianForm::TTV, 6), gauss_b(HamiltonianForm::TTV, 6);
  for (int s = 0; s < 1000; ++s) {
    gauss_a.step(general, a, 0.001);
    gauss_b.step(product, b, 0.001);
  }
  const double difference = largest_difference(a, b);
  MESSAGE("paper1d, gauss 3 stages, 1000 steps of 0.001 from (2, 0): largest difference " << difference);
  CHECK(difference <= 1e-13);
  EnergyEvaluator energy(HamiltonianForm::TTV);
  CHECK(energy.evaluate_one(general, a) == doctest::Approx(energy.evaluate_one(product, a)).epsilon(1e-15));
}

namespace {
// MagneticBottle with a hand-written gradient whose dH/dp_2 is wrong (v_z + 0.01).
struct WrongGradient : MagneticBottle {
  using MagneticBottle::MagneticBottle;
  void grad_H(sdk::Vector<double> q, sdk::Vector<double> p, std::span<double> dH_dq, std::span<double> dH_dp) const {
    sdk::HamiltonianAdapter<MagneticBottle, sdk::Derivatives::automatic>::from_json(R"({"mirror": 0.5})")
        .grad_H(q, p, dH_dq, dH_dp, 1);
    dH_dp[2] += 0.01;
  }
};
}  // namespace

TEST_CASE("general H: the derivative checker compares grad_H and hvp_H with finite differences") {
  const auto bottle = sdk::HamiltonianAdapter<MagneticBottle>::from_json(R"({"mirror": 0.5, "omega": 0.3})");
  const DerivativeCheckReport good = check_hamiltonian_derivatives(bottle);
  MESSAGE(good.summary());
  CHECK(good.passed());
  CHECK(good.comparisons == 16 * 2 * 6);  // grad_H and hvp_H, 6 components, 16 points
  const auto wrong = sdk::HamiltonianAdapter<WrongGradient>::from_json(R"({"mirror": 0.5})");
  static_assert(decltype(wrong)::analytic_grad_H);
  const DerivativeCheckReport bad = check_hamiltonian_derivatives(wrong);
  REQUIRE_FALSE(bad.passed());
  CHECK(bad.mismatches[0].function == "grad_H");
  CHECK(bad.mismatches[0].component == 5);  // dH/dp_2, after the three of dH/dq
  CHECK(bad.summary().find("grad_H[5] at (q, p) = (") != std::string::npos);
}

namespace {
// H = p^2/2 + sqrt(q): grad H is NaN for q < 0 and infinite at q = 0, where H is not differentiable.
struct SquareRootWell {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S H(sdk::Vector<S> q, sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0 + sdk::sqrt(q[0]);
  }
};
}  // namespace

TEST_CASE("general H: a Gauss step that reaches a point where grad H is not finite names that point, not dt") {
  const sdk::HamiltonianAdapter<SquareRootWell> model;
  GaussLegendre gauss(HamiltonianForm::TTV, 4);
  // State 0 starts where H is not defined; state 1 is fine for this step.
  PhaseSpaceBatch x(1, 2);
  x.q()[0] = -0.5;
  x.q()[1] = 1.0;
  x.p()[1] = -0.1;
  const auto failures = gauss.try_step(model, x, 0.01);
  REQUIRE(failures.size() == 1);
  CHECK(failures[0].state == 0);
  INFO(failures[0].reason);
  CHECK(failures[0].reason.find("grad H is not finite at stage 1 of iteration 1, q = (-0.5), p = (0)") == 0);
  CHECK(failures[0].reason.find("not differentiable") != std::string::npos);
  CHECK(failures[0].reason.find("smaller dt") == std::string::npos);
  CHECK(x.q()[0] == -0.5);  // the failed state keeps its starting point
  CHECK(x.q()[1] != 1.0);
}

namespace {
// H = p^2/2 + q^4/4: defined and smooth everywhere; a step far too large for its time scale makes the fixed-point
// iteration diverge until grad H overflows.
struct QuarticWell {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S H(sdk::Vector<S> q, sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0 + q[0] * q[0] * q[0] * q[0] / 4.0;
  }
};
}  // namespace

TEST_CASE("general H: a Gauss step whose iteration diverges to where grad H overflows names dt, not H") {
  const sdk::HamiltonianAdapter<QuarticWell> model;
  GaussLegendre gauss(HamiltonianForm::TTV, 4);
  PhaseSpaceBatch x(1, 1);
  x.q()[0] = 1.0;
  const auto failures = gauss.try_step(model, x, 5.0);
  REQUIRE(failures.size() == 1);
  INFO(failures[0].reason);
  CHECK(failures[0].reason.find("grad H is not finite at stage ") == 0);
  CHECK(failures[0].reason.find("far from the step's start q = (1), p = (0)") != std::string::npos);
  CHECK(failures[0].reason.find("the fixed-point iteration diverged, which a smaller dt prevents") !=
        std::string::npos);
  CHECK(x.q()[0] == 1.0);
  // The same state with a step the iteration takes: no failure.
  CHECK(gauss.try_step(model, x, 0.05).empty());
}

}  // namespace test_general_hamiltonian
