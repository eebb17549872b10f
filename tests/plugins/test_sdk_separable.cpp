// The SDK's separable part: a model class with templated K(p) and/or U(q) makes ModelAdapter a
// nonsep::ModelWithSeparablePart, with K and U differentiated automatically (or analytically where the class says
// so); the shipped mathews_lakshmanan and variable_mass2d classes agree with their hand-written twins of the tests;
// a class without K and U leaves the adapter without the separable functions.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "mathews_lakshmanan/mathews_lakshmanan.hpp"
#include "nonsep/core/base/model.hpp"
#include "nonsep/derivative_checker.hpp"
#include "paper1d/paper1d.hpp"
#include "support/models.hpp"
#include "variable_mass2d/variable_mass2d.hpp"

namespace test_sdk_separable {

namespace {

using OscillatorAdapter = nonsep::sdk::ModelAdapter<MathewsLakshmanan>;
using OscillatorByAD = nonsep::sdk::ModelAdapter<MathewsLakshmanan, nonsep::sdk::Derivatives::automatic>;
using PlaneAdapter = nonsep::sdk::ModelAdapter<VariableMass2D>;

static_assert(nonsep::ModelWithSeparablePart<OscillatorAdapter>);
static_assert(nonsep::ModelWithSeparablePart<PlaneAdapter>);
static_assert(!nonsep::ModelWithSeparablePart<nonsep::sdk::ModelAdapter<Paper1D>>);
static_assert(OscillatorAdapter::analytic_grad_U && !OscillatorByAD::analytic_grad_U);
static_assert(!PlaneAdapter::analytic_grad_K && !PlaneAdapter::analytic_hessian_U);

// Largest |a - b| / max(1, |b|) of f applied to both models at the same points.
template <class A, class B, class F>
double largest_difference(const A& a, const B& b, std::size_t per_state, const std::vector<double>& x, F&& f) {
  const std::size_t count = x.size() / a.dimension();
  std::vector<double> out_a(count * per_state), out_b(count * per_state);
  f(a, x, out_a, count);
  f(b, x, out_b, count);
  double largest = 0.0;
  for (std::size_t i = 0; i < out_a.size(); ++i)
    largest = std::max(largest, std::abs(out_a[i] - out_b[i]) / std::max(1.0, std::abs(out_b[i])));
  return largest;
}

}  // namespace

TEST_CASE("SDK separable part: the adapters announce K and U and agree with the hand-written twins") {
  const OscillatorAdapter oscillator;
  const PlaneAdapter plane;
  CHECK_FALSE(oscillator.has_K());
  CHECK(oscillator.has_U());
  CHECK(plane.has_K());
  CHECK(plane.has_U());
  const nonsep::testing::MathewsLakshmanan oscillator_twin;
  const nonsep::testing::VariableMass2D plane_twin;
  const std::vector<double> x1{0.3, -1.2, 2.0, 0.0}, x2{0.3, -1.2, 2.0, 0.5, -0.7, 0.1};
  auto each = [&](const auto& model, const auto& twin, const std::vector<double>& x) {
    const std::size_t n = model.dimension();
    CHECK(largest_difference(model, twin, 1, x,
                             [](const auto& m, auto& in, auto& out, std::size_t c) { m.value_K(in, out, c); }) < 1e-15);
    CHECK(largest_difference(model, twin, 1, x,
                             [](const auto& m, auto& in, auto& out, std::size_t c) { m.value_U(in, out, c); }) < 1e-15);
    CHECK(largest_difference(model, twin, n, x,
                             [](const auto& m, auto& in, auto& out, std::size_t c) { m.grad_K(in, out, c); }) < 1e-15);
    CHECK(largest_difference(model, twin, n, x,
                             [](const auto& m, auto& in, auto& out, std::size_t c) { m.grad_U(in, out, c); }) < 1e-15);
    CHECK(largest_difference(model, twin, n * n, x, [](const auto& m, auto& in, auto& out, std::size_t c) {
            m.hessian_K(in, out, c);
          }) < 1e-14);
    CHECK(largest_difference(model, twin, n * n, x, [](const auto& m, auto& in, auto& out, std::size_t c) {
            m.hessian_U(in, out, c);
          }) < 1e-14);
    CHECK(largest_difference(model, twin, n, x,
                             [](const auto& m, auto& in, auto& out, std::size_t c) { m.grad_V(in, out, c); }) < 1e-15);
  };
  each(oscillator, oscillator_twin, x1);
  each(plane, plane_twin, x2);
  // The analytic grad U against automatic differentiation, and the derivative checker on both adapters.
  CHECK(largest_difference(oscillator, OscillatorByAD{}, 1, x1,
                           [](const auto& m, auto& in, auto& out, std::size_t c) { m.grad_U(in, out, c); }) < 1e-15);
  for (const auto& report :
       {nonsep::check_separable_derivatives(oscillator), nonsep::check_separable_derivatives(plane)}) {
    INFO(report.summary());
    CHECK(report.comparisons > 0);
    CHECK(report.passed());
  }
}

TEST_CASE("SDK separable part: spans too short for the batch are refused with the sizes named") {
  const PlaneAdapter plane;
  std::vector<double> x(4), out(3);
  CHECK_THROWS_WITH_AS(plane.grad_U(x, out, 2), doctest::Contains("given spans of 4 and 3 numbers"),
                       nonsep::InvalidArgument);
  const OscillatorAdapter oscillator;
  std::vector<double> one(1), none(0);
  CHECK_THROWS_AS(oscillator.grad_K(one, none, 1), nonsep::InvalidArgument);
}

}  // namespace test_sdk_separable
