// The tangent maps of the basic step, the triplet composition and MPE: they are the derivative of the numerical
// map (central differences of the map itself), symplectic for basic and triplet and not for MPE, they leave the
// states' numbers bit for bit those of the plain steppers, and they count their Hessian evaluations.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "support/models.hpp"
#include "support/phase_space_jacobian.hpp"

namespace test_tangent_map {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;
using nonsep::testing::Paper2D;

namespace {

// dt as a value the compiler cannot see: GCC folds std::cbrt of a literal correctly rounded, while glibc's cbrt
// at run time may differ in the last bit (cbrt(0.01) does), so two code paths, one inlined with a literal dt and
// one not, would differ by that bit before the steppers did anything.
double opaque(double dt) {
  volatile double value = dt;
  return value;
}

const std::array<HamiltonianForm, 2> forms{HamiltonianForm::TTV, HamiltonianForm::VVT};

// The specs every property is checked on: basic, triplet of orders 4/3 and 2, MPE of orders 4/3 and 2.
std::vector<IntegratorSpec> all_specs(HamiltonianForm form) {
  const double t2 = ChinCoefficients::default_t2();
  return {{"basic", ChinOptions{Fraction(2, 3), -2.5}, form},
          {"triplet", ChinOptions{Fraction(4, 3), t2}, form},
          {"triplet", ChinOptions{Fraction(2), t2}, form},
          {"mpe", ChinOptions{Fraction(4, 3), t2}, form},
          {"mpe", ChinOptions{Fraction(2), t2}, form}};
}

// `steps` steps of the tangent integrator from x: the Jacobian of the `steps`-step map.
template <class M>
Eigen::MatrixXd tangent_jacobian(const M& model, const IntegratorSpec& spec, PhaseSpaceBatch x, double dt, int steps) {
  auto tangents = testing::identity_tangents(x.dimension());
  TangentIntegrator integrator(spec);
  for (int s = 0; s < steps; ++s) integrator.step(model, x, tangents, dt);
  return testing::as_matrix(tangents);
}

// The same Jacobian by central differences of the plain integrator's map, step h (support/finite_difference.hpp).
template <class M>
Eigen::MatrixXd difference_jacobian(const M& model, const IntegratorSpec& spec, const PhaseSpaceBatch& x0, double dt,
                                    int steps, double h) {
  return testing::jacobian_by_differences(testing::integrator_map(model, spec, dt, steps), testing::phase_point(x0), h);
}

// max |M^T J M - J| / max(1, max |M|^2): zero to round-off for a symplectic M.
double symplecticity_defect(const Eigen::MatrixXd& m) { return testing::symplecticity_defect(m, true); }

template <class M>
void check_against_differences(const M& model, const PhaseSpaceBatch& x0, double dt) {
  for (const auto form : forms)
    for (const auto& spec : all_specs(form)) {
      CAPTURE(spec.scheme);
      CAPTURE(std::get<ChinOptions>(spec.options).order.to_string());
      CAPTURE(static_cast<int>(form));
      // Three steps, so that the cached Hessian is reused across steps.
      const Eigen::MatrixXd exact = tangent_jacobian(model, spec, x0, dt, 3);
      const Eigen::MatrixXd differences = difference_jacobian(model, spec, x0, dt, 3, 1e-5);
      const double relative = (exact - differences).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
      CHECK(relative < 1e-7);
      CHECK((exact - Eigen::MatrixXd::Identity(exact.rows(), exact.cols())).cwiseAbs().maxCoeff() > 1e-3);  // moved
    }
}

}  // namespace

TEST_CASE("the tangent map is the derivative of the numerical map (central differences, relative 1e-7)") {
  check_against_differences(Paper1D{}, PhaseSpaceBatch::single(std::vector{1.2}, std::vector{0.5}), 0.02);
  check_against_differences(Coupled2D{}, PhaseSpaceBatch::single(std::vector{0.6, -0.4}, std::vector{0.3, 0.2}), 0.02);
  check_against_differences(Paper2D{}, PhaseSpaceBatch::single(std::vector{-0.75, 0.3}, std::vector{-1.5, 0.2}), 0.01);
}

TEST_CASE("the tangent map of basic and triplet is symplectic to 1e-12 per step, and MPE's is not") {
  for (const auto form : forms)
    for (const auto& spec : all_specs(form)) {
      CAPTURE(spec.scheme);
      CAPTURE(std::get<ChinOptions>(spec.options).order.to_string());
      CAPTURE(static_cast<int>(form));
      const bool symplectic = spec.scheme != "mpe";
      // dt = 0.02: at 0.05 the order-2 triplet's largest basic step (6.4 dt) overflows these states.
      const auto x2 = PhaseSpaceBatch::single(std::vector{0.6, -0.4}, std::vector{0.3, 0.2});
      const auto x1 = PhaseSpaceBatch::single(std::vector{1.2}, std::vector{0.5});
      const double defects[] = {symplecticity_defect(tangent_jacobian(Coupled2D{}, spec, x2, 0.02, 1)),
                                symplecticity_defect(tangent_jacobian(Paper2D{}, spec, x2, 0.02, 1)),
                                symplecticity_defect(tangent_jacobian(Paper1D{}, spec, x1, 0.02, 1))};
      for (const double defect : defects) {
        CAPTURE(defect);
        if (symplectic)
          CHECK(defect < 1e-12);
        else
          CHECK(defect > 1e-10);  // measured 2e-9 .. 7e-4; basic and triplet give 0 .. 9e-16
      }
    }
}

TEST_CASE("the tangent map of a step of dt followed by one of -dt is the identity (basic and triplet)") {
  for (const auto form : forms)
    for (const auto& spec : all_specs(form)) {
      if (spec.scheme == "mpe") continue;
      CAPTURE(spec.scheme);
      auto x = PhaseSpaceBatch::single(std::vector{0.6, -0.4}, std::vector{0.3, 0.2});
      auto tangents = testing::identity_tangents(2);
      TangentIntegrator integrator(spec);
      integrator.step(Paper2D{}, x, tangents, 0.03);
      integrator.step(Paper2D{}, x, tangents, -0.03);
      CHECK((testing::as_matrix(tangents) - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff() < 1e-12);
    }
}

TEST_CASE("stepping with tangent vectors leaves the states bit for bit as the plain steppers step them") {
  for (const auto form : forms)
    for (const auto& spec : all_specs(form))
      for (const std::size_t k : {std::size_t{1}, std::size_t{4}}) {
        CAPTURE(spec.scheme);
        CAPTURE(std::get<ChinOptions>(spec.options).order.to_string());
        CAPTURE(k);
        PhaseSpaceBatch plain(2, 3);
        const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
        std::copy(std::begin(qs), std::end(qs), plain.q().begin());
        std::copy(std::begin(ps), std::end(ps), plain.p().begin());
        auto with_tangents = plain;
        PhaseSpaceBatch tangents(2, 3 * k);
        for (std::size_t i = 0; i < tangents.size(); ++i) tangents.q()[i] = 0.1 * static_cast<double>(i % 5) + 0.3;
        Integrator integrator(spec);
        TangentIntegrator tangent(spec);
        const double dt = opaque(0.01);
        for (int s = 0; s < 7; ++s) {
          integrator.step(Paper2D{}, plain, dt);
          tangent.step(Paper2D{}, with_tangents, tangents, dt);
        }
        CHECK(with_tangents == plain);
        if (spec.scheme != "mpe") CHECK(tangent.evaluations() == integrator.evaluations());
      }
}

TEST_CASE("a batch of states with tangent vectors equals each state stepped alone, bit for bit") {
  // dt as the product has it, known only at run time: with a literal, the compiler may fold cbrt(dt) at one call
  // site (correctly rounded) and call the library at the other, and the two can differ in the last bit.
  const volatile double opaque_dt = 0.01;
  const double dt = opaque_dt;
  const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
  for (const auto& spec : all_specs(HamiltonianForm::TTV)) {
    CAPTURE(spec.scheme);
    PhaseSpaceBatch batch(2, 3);
    std::copy(std::begin(qs), std::end(qs), batch.q().begin());
    std::copy(std::begin(ps), std::end(ps), batch.p().begin());
    PhaseSpaceBatch tangents(2, 3 * 2);
    for (std::size_t i = 0; i < tangents.size(); ++i) tangents.p()[i] = 1.0 / static_cast<double>(i + 1);
    TangentIntegrator together(spec);
    for (int s = 0; s < 5; ++s) together.step(Coupled2D{}, batch, tangents, dt);
    for (std::size_t b = 0; b < 3; ++b) {
      auto x = PhaseSpaceBatch::single(std::vector{qs[2 * b], qs[2 * b + 1]}, std::vector{ps[2 * b], ps[2 * b + 1]});
      PhaseSpaceBatch t(2, 2);
      for (std::size_t i = 0; i < t.size(); ++i) t.p()[i] = 1.0 / static_cast<double>(b * 4 + i + 1);
      TangentIntegrator alone(spec);
      for (int s = 0; s < 5; ++s) alone.step(Coupled2D{}, x, t, dt);
      CHECK(x.q()[0] == batch.q(b)[0]);
      CHECK(x.p()[1] == batch.p(b)[1]);
      for (std::size_t j = 0; j < 2; ++j)
        for (std::size_t i = 0; i < 2; ++i) {
          CHECK(t.q(j)[i] == tangents.q(2 * b + j)[i]);
          CHECK(t.p(j)[i] == tangents.p(2 * b + j)[i]);
        }
    }
  }
}

TEST_CASE("Hessian evaluations: 4 Hess T + 4 Hess V per basic step, plus one at the start, per state") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    const bool ttv = form == HamiltonianForm::TTV;
    PhaseSpaceBatch x(1, 3), tangents(1, 3);
    x.q()[0] = 0.5, x.q()[1] = 1.0, x.q()[2] = 1.5;
    tangents.q()[0] = tangents.q()[1] = tangents.q()[2] = 1.0;
    TangentBasicStep basic{ChinBasicStep(form)};
    for (double dt : {0.01, -0.02, 0.013}) basic.step(Paper1D{}, x, tangents, dt);
    const std::uint64_t outer = 3 * (4 * 3 + 1), inner = 3 * 4 * 3;
    CHECK(basic.hessian_evaluations().hessian_V == (ttv ? outer : inner));
    CHECK(basic.hessian_evaluations().hessian_T == (ttv ? inner : outer));
    // The gradients are counted as the plain basic step counts them.
    CHECK(basic.evaluations().grad_V == (ttv ? outer : inner));
  }
  // Triplet of order 2: 9 basic steps per step.
  TangentTripletComposition triplet(TripletComposition<SeparableBasicStep>(SeparableBasicStep(), 2));
  auto x = PhaseSpaceBatch::single(std::vector{0.5, 0.2}, std::vector{0.1, 0.3});
  auto tangents = testing::identity_tangents(2);
  for (int s = 0; s < 4; ++s) triplet.step(Paper2D{}, x, tangents, 0.01);
  CHECK(triplet.hessian_evaluations().hessian_T == 4 * 9 * 4);
  CHECK(triplet.hessian_evaluations().hessian_V == 4 * 9 * 4 + 1);
}

TEST_CASE("tangent vectors that do not fit the states are refused with the shapes named") {
  auto x = PhaseSpaceBatch::single(std::vector{0.5, 0.2}, std::vector{0.1, 0.3});
  TangentBasicStep basic;
  PhaseSpaceBatch too_many(2, 5), wrong_dimension(1, 2);
  for (PhaseSpaceBatch* t : {&too_many, &wrong_dimension}) {
    std::string message;
    try {
      basic.step(Paper2D{}, x, *t, 0.01);
    } catch (const InvalidArgument& e) {
      message = e.what();
    }
    CAPTURE(message);
    CHECK((message.find("1 <= k <= 4 (found 5") != std::string::npos ||
           message.find("tangent vectors have dimension 1 but the states have dimension 2") != std::string::npos));
  }
  CHECK_THROWS_AS(TangentIntegrator(IntegratorSpec{"triplet", ChinOptions{Fraction(1, 3)}}), InvalidArgument);
}

}  // namespace test_tangent_map
