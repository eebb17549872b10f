// Structural properties of the schemes of the catalogue on models with a separable part K(p) + U(q)
// (separable_composition.hpp): time reversibility, symplecticity (one-step Jacobian, with MPE as the negative
// control), batch = single bit for bit, MPE's batched terms = term by term, the energy and grad H of the full H, the
// tangent map including the separable flows' linearisations, evaluation counts; and a model with K = U = 0 stepped
// bit for bit as the basic step, the triplet and MPE over ChinBasicStep step it (the numbers before the separable
// part existed).
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "support/finite_difference.hpp"
#include "support/models.hpp"
#include "support/phase_space_jacobian.hpp"

namespace test_separable_properties {

using namespace nonsep;
using nonsep::testing::MathewsLakshmanan;
using nonsep::testing::VariableMass2D;

namespace {

const std::array<HamiltonianForm, 2> forms{HamiltonianForm::TTV, HamiltonianForm::VVT};
const double t2_default = ChinCoefficients::default_t2();

PhaseSpaceBatch state(std::vector<double> q, std::vector<double> p) { return PhaseSpaceBatch::single(q, p); }

double max_difference(const PhaseSpaceBatch& a, const PhaseSpaceBatch& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    d = std::max({d, std::abs(a.q()[i] - b.q()[i]), std::abs(a.p()[i] - b.p()[i])});
  return d;
}

template <class M>
double symplecticity_defect(const M& model, const IntegratorSpec& spec, const PhaseSpaceBatch& x0, double dt) {
  return testing::symplecticity_defect(
      testing::jacobian_by_differences(testing::integrator_map(model, spec, dt), testing::phase_point(x0), 1e-6));
}

// The symplectic schemes and the orders checked on them.
std::vector<IntegratorSpec> symplectic_specs(HamiltonianForm form) {
  return {{"basic", ChinOptions{Fraction(2, 3), -2.5}, form},
          {"triplet", ChinOptions{Fraction(4, 3), t2_default}, form},
          {"triplet", ChinOptions{Fraction(2), t2_default}, form},
          {"triplet", ChinOptions{Fraction(8, 3), t2_default}, form}};
}

// VariableMass2D's product part alone, as a model type without the separable concept.
struct ProductOnly2D {
  VariableMass2D model;
  std::size_t dimension() const { return 2; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    model.grad_T(p, out, count);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    model.grad_V(q, out, count);
  }
};

}  // namespace

TEST_CASE("separable part: a step of dt followed by one of -dt returns to the start (symplectic schemes, both forms)") {
  for (const auto form : forms)
    for (const auto& spec : symplectic_specs(form)) {
      CAPTURE(spec.scheme);
      CAPTURE(std::get<ChinOptions>(spec.options).order.to_string());
      CAPTURE(static_cast<int>(form));
      Integrator integrator(spec);
      const auto start1 = state({1.2}, {0.4});
      auto x1 = start1;
      integrator.step(MathewsLakshmanan{}, x1, 0.01);
      CHECK(max_difference(x1, start1) > 1e-4);
      integrator.step(MathewsLakshmanan{}, x1, -0.01);
      CHECK(max_difference(x1, start1) < 1e-12);
      const auto start2 = state({0.7, -0.3}, {0.2, 0.5});
      auto x2 = start2;
      integrator.step(VariableMass2D{}, x2, 0.02);
      integrator.step(VariableMass2D{}, x2, -0.02);
      CHECK(max_difference(x2, start2) < 1e-12);
    }
}

TEST_CASE("separable part: the one-step map is symplectic for basic and triplet, and MPE is not") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    for (const auto& spec : symplectic_specs(form)) {
      CAPTURE(spec.scheme);
      CAPTURE(std::get<ChinOptions>(spec.options).order.to_string());
      CHECK(symplecticity_defect(MathewsLakshmanan{}, spec, state({1.2}, {0.5}), 0.05) < 1e-8);
      CHECK(symplecticity_defect(VariableMass2D{}, spec, state({0.6, -0.4}, {0.3, 0.2}), 0.05) < 1e-8);
      VariableMass2D only_K;
      only_K.with_U = false;
      CHECK(symplecticity_defect(only_K, spec, state({0.6, -0.4}, {0.3, 0.2}), 0.05) < 1e-8);
    }
    const IntegratorSpec mpe{"mpe", ChinOptions{Fraction(4, 3), t2_default}, form};
    CHECK(symplecticity_defect(MathewsLakshmanan{}, mpe, state({1.2}, {0.5}), 0.1) > 1e-6);
    CHECK(symplecticity_defect(VariableMass2D{}, mpe, state({0.6, -0.4}, {0.3, 0.2}), 0.1) > 1e-6);
  }
}

TEST_CASE("separable part: stepping a batch equals stepping each state alone, bit for bit, every scheme") {
  IntegratorSpec gauss{"gauss"};
  const std::vector<IntegratorSpec> specs = {{"basic", ChinOptions{Fraction(2, 3)}},
                                             {"triplet", ChinOptions{Fraction(4, 3)}},
                                             {"mpe", ChinOptions{Fraction(2)}},
                                             {"tao", TaoOptions{Fraction(2)}},
                                             {"implicit_midpoint"},
                                             gauss};
  for (const auto& spec : specs) {
    CAPTURE(spec.scheme);
    PhaseSpaceBatch batch(2, 3);
    const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
    std::copy(std::begin(qs), std::end(qs), batch.q().begin());
    std::copy(std::begin(ps), std::end(ps), batch.p().begin());
    Integrator together(spec);
    for (int s = 0; s < 10; ++s) together.step(VariableMass2D{}, batch, 0.01);
    for (std::size_t b = 0; b < 3; ++b) {
      auto x = state({qs[2 * b], qs[2 * b + 1]}, {ps[2 * b], ps[2 * b + 1]});
      Integrator alone(spec);
      for (int s = 0; s < 10; ++s) alone.step(VariableMass2D{}, x, 0.01);
      CHECK(x.q()[0] == batch.q(b)[0]);
      CHECK(x.q()[1] == batch.q(b)[1]);
      CHECK(x.p()[0] == batch.p(b)[0]);
      CHECK(x.p()[1] == batch.p(b)[1]);
    }
  }
}

TEST_CASE("separable part: MPE's batched terms give the term-by-term numbers and evaluation counts bit for bit") {
  for (const auto form : forms)
    for (int m = 1; m <= 4; ++m) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(m);
      PhaseSpaceBatch batched(2, 3);
      const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
      std::copy(std::begin(qs), std::end(qs), batched.q().begin());
      std::copy(std::begin(ps), std::end(ps), batched.p().begin());
      PhaseSpaceBatch sequential = batched;
      MultiProductExpansion<SeparableBasicStep> together(SeparableBasicStep(ChinBasicStep(form)), m),
          one_by_one(SeparableBasicStep(ChinBasicStep(form)), m);
      for (double dt : {0.01, 0.01, -0.004, 0.02}) {
        together.step(VariableMass2D{}, batched, dt);
        one_by_one.step_term_by_term(VariableMass2D{}, sequential, dt);
        CHECK(batched == sequential);
      }
      CHECK(together.evaluations() == one_by_one.evaluations());
    }
}

TEST_CASE("separable part: evaluations per step, 2 grad U without K, 4 grad U and 2 grad K with both") {
  const double q[] = {0.4}, p[] = {0.1};
  auto x = PhaseSpaceBatch::single(q, p);
  Integrator basic(IntegratorSpec{"basic", ChinOptions{Fraction(2, 3)}});
  basic.step_n(MathewsLakshmanan{}, x, 0.01, 5);
  CHECK(basic.evaluations().grad_U == 10);
  CHECK(basic.evaluations().grad_K == 0);
  CHECK(basic.evaluations().grad_T == 20);
  CHECK(basic.evaluations().grad_V == 21);  // no K: the half-kicks leave q, so first-same-as-last holds
  auto y = state({0.4, 0.2}, {0.1, -0.3});
  Integrator triplet(IntegratorSpec{"triplet", ChinOptions{Fraction(4, 3)}});
  triplet.step(VariableMass2D{}, y, 0.01);
  CHECK(triplet.evaluations().grad_U == 12);
  CHECK(triplet.evaluations().grad_K == 6);
  CHECK(triplet.evaluations().grad_V == 12 + 3);  // K moves q before every basic step: its first gradient again
}

TEST_CASE("separable part: energy and grad H are those of the full H = T_i V_ij T_j + K + U") {
  const double z[] = {0.4, -0.9, 0.7, -0.3};
  for (const bool with_K : {false, true})
    for (const bool with_U : {false, true}) {
      VariableMass2D model;
      model.with_K = with_K;
      model.with_U = with_U;
      const auto x = state({z[0], z[1]}, {z[2], z[3]});
      EnergyEvaluator energy(HamiltonianForm::TTV);
      CHECK(energy.evaluate_one(model, x) == doctest::Approx(model.hamiltonian(z)).epsilon(1e-14));
      HamiltonianGradient gradient(HamiltonianForm::TTV);
      std::vector<double> dq(2), dp(2);
      gradient.evaluate(model, x.q(), x.p(), dq, dp, 1);
      const std::vector<double> point(z, z + 4);
      for (std::size_t k = 0; k < 4; ++k) {
        const auto h = [&](const std::vector<double>& w) { return std::vector<double>{model.hamiltonian(w.data())}; };
        const double expected = testing::central_difference_along(h, point, k, 1e-5)[0];
        CHECK((k < 2 ? dq[k] : dp[k - 2]) == doctest::Approx(expected).epsilon(1e-8));
      }
    }
}

TEST_CASE("separable part: the tangent map is the derivative of the step, symplectic for basic and triplet") {
  for (const auto form : forms)
    for (const auto& spec : {IntegratorSpec{"basic", ChinOptions{Fraction(2, 3), -2.5}, form},
                             IntegratorSpec{"triplet", ChinOptions{Fraction(4, 3), t2_default}, form},
                             IntegratorSpec{"mpe", ChinOptions{Fraction(2), t2_default}, form}}) {
      CAPTURE(spec.scheme);
      CAPTURE(static_cast<int>(form));
      const VariableMass2D model;
      const auto x0 = state({0.6, -0.4}, {0.3, 0.2});
      auto x = x0;
      auto tangents = testing::identity_tangents(2);
      TangentIntegrator tangent(spec);
      for (int s = 0; s < 3; ++s) tangent.step(model, x, tangents, 0.05);
      const Eigen::MatrixXd by_map = testing::as_matrix(tangents);
      const Eigen::MatrixXd by_differences = testing::jacobian_by_differences(
          testing::integrator_map(model, spec, 0.05, 3), testing::phase_point(x0), 1e-6);
      CHECK((by_map - by_differences).cwiseAbs().maxCoeff() < 1e-8);
      auto plain = x0;
      Integrator integrator(spec);
      for (int s = 0; s < 3; ++s) integrator.step(model, plain, 0.05);
      CHECK(plain == x);
      if (spec.scheme != "mpe") CHECK(testing::symplecticity_defect(by_map) < 1e-12);
      CHECK(tangent.hessian_evaluations().hessian_U > 0);
      CHECK(tangent.hessian_evaluations().hessian_K > 0);
    }
}

TEST_CASE("a model with K = U = 0 is stepped bit for bit as by the steppers over ChinBasicStep alone") {
  VariableMass2D none;
  none.with_K = false;
  none.with_U = false;
  const ProductOnly2D product;
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    const auto start = state({0.6, -0.4}, {0.3, 0.2});
    auto check_scheme = [&](const IntegratorSpec& spec, auto reference) {
      CAPTURE(spec.scheme);
      auto a = start, b = start, c = start;
      Integrator integrator(spec), other(spec);
      for (double dt : {0.01, 0.02, -0.005}) {
        integrator.step(none, a, dt);
        other.step(product, b, dt);
        reference.step(product, c, dt);
      }
      CHECK(a == c);
      CHECK(b == c);
      CHECK(integrator.evaluations() == reference.evaluations());
    };
    check_scheme(IntegratorSpec{"basic", ChinOptions{Fraction(2, 3), t2_default}, form}, ChinBasicStep(form));
    check_scheme(IntegratorSpec{"triplet", ChinOptions{Fraction(2), t2_default}, form},
                 TripletComposition<ChinBasicStep>(ChinBasicStep(form), 2));
    check_scheme(IntegratorSpec{"mpe", ChinOptions{Fraction(2), t2_default}, form},
                 MultiProductExpansion<ChinBasicStep>(ChinBasicStep(form), 3));
    auto a = start, b = start;
    auto ta = testing::identity_tangents(2), tb = testing::identity_tangents(2);
    TangentIntegrator tangent(IntegratorSpec{"basic", ChinOptions{Fraction(2, 3), t2_default}, form});
    TangentBasicStep reference{ChinBasicStep(form)};
    tangent.step(none, a, ta, 0.02);
    reference.step(none, b, tb, 0.02);
    CHECK(a == b);
    CHECK(ta == tb);
    CHECK(tangent.hessian_evaluations().hessian_K == 0);
  }
}

}  // namespace test_separable_properties
