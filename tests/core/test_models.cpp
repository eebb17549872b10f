// The models compiled into the tests have hand-written derivatives; check them with the SDK's derivative checker
// (5-point differences of T and V for the gradients, of the gradients for the Hessians) before anything relies on
// them. A deliberately wrong model shows that the check can fail.
#include <doctest/doctest.h>

#include <cstddef>
#include <span>
#include <vector>

#include "nonsep/derivative_checker.hpp"
#include "support/models.hpp"

namespace test_models {

namespace {

// Largest error (relative to max(1, |difference|)) of every gradient and Hessian entry at 16 random points in
// [-1.5, 1.5]^n and two fixed ones; the differences are accurate to about 1e-11 for these polynomials.
template <class M>
nonsep::DerivativeCheckReport check(const M& model) {
  nonsep::DerivativeCheckOptions options;
  options.tolerance = 1e-8;
  options.check_hessian_vector_products = false;  // the compiled-in models have dense Hessians only
  options.points = model.dimension() == 1 ? std::vector<std::vector<double>>{{0.8}, {-1.4}}
                                          : std::vector<std::vector<double>>{{0.3, -0.2}, {-1.1, 0.7}};
  return nonsep::check_derivatives(model, options);
}

// Coupled2D with the mixed term of its Hessian of V off by 1e-4: the negative control.
struct WrongHessian : nonsep::testing::Coupled2D {
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    Coupled2D::hessian_V(q, out, count);
    for (std::size_t b = 0; b < count; ++b) out[4 * b + 1] += 1e-4;
  }
};

}  // namespace

TEST_CASE("test models: gradients are those of T and V, Hessians those of the gradients") {
  // With the models' d3T/d3V, the checker also compares those with differences of u^T H u.
  for (const auto& report : {check(nonsep::testing::Paper1D{}), check(nonsep::testing::Coupled2D{})}) {
    INFO(report.summary());
    CHECK(report.skipped.empty());
    CHECK(report.comparisons > 0);
    CHECK(report.passed());
    CHECK(report.largest_error < 1e-8);
  }
  const auto wrong = check(WrongHessian{});
  CHECK_FALSE(wrong.passed());
  REQUIRE(!wrong.mismatches.empty());
  CHECK(wrong.mismatches.front().function == "hessian_V");
  CHECK(wrong.mismatches.front().component == 1);
}

TEST_CASE("test models: batched third derivatives read each state's own point and direction") {
  const nonsep::testing::Coupled2D model;
  const std::vector<double> xs{0.3, -0.2, -1.1, 0.7}, us{0.6, -1.3, 0.2, 0.9}, x1{-1.1, 0.7}, u1{0.2, 0.9};
  std::vector<double> together(4), alone(2);
  model.d3V(xs, us, together, 2);
  model.d3V(x1, u1, alone, 1);
  CHECK((together[2] == alone[0] && together[3] == alone[1]));
  model.d3T(xs, us, together, 2);
  model.d3T(x1, u1, alone, 1);
  CHECK((together[2] == alone[0] && together[3] == alone[1]));
}

TEST_CASE("test models: paper2d and radial2d Hessians, and hamiltonian() as grad T . Hess V grad T") {
  const nonsep::testing::Paper2D p2{0.25};
  const nonsep::testing::Radial2D r2;
  for (const auto& report : {check(p2), check(r2)}) {  // no values: gradients are checked through the plugins
    INFO(report.summary());
    CHECK(report.comparisons > 0);
    CHECK(report.passed());
  }
  const double x[4] = {0.4, -0.9, 0.7, -0.3};
  auto quadratic_form = [&](const auto& model) {
    double g[2], h[4];
    model.grad_T(std::span<const double>(x + 2, 2), g, 1);
    model.hessian_V(std::span<const double>(x, 2), h, 1);
    return g[0] * (h[0] * g[0] + h[1] * g[1]) + g[1] * (h[2] * g[0] + h[3] * g[1]);
  };
  CHECK(p2.hamiltonian(x) == doctest::Approx(quadratic_form(p2)).epsilon(1e-14));
  CHECK(r2.hamiltonian(x) == doctest::Approx(quadratic_form(r2)).epsilon(1e-14));
  const double x1[2] = {0.4, -0.9};
  CHECK(nonsep::testing::Paper1D{}.hamiltonian(x1) ==
        doctest::Approx(nonsep::testing::Paper1D::H_TTV(0.4, -0.9)).epsilon(1e-15));
}

TEST_CASE("test models with a separable part: T, V, K and U derivatives, and a wrong grad U is found") {
  const nonsep::testing::MathewsLakshmanan oscillator;
  const nonsep::testing::VariableMass2D plane;
  for (const auto& report : {check(oscillator), check(plane), nonsep::check_separable_derivatives(oscillator),
                             nonsep::check_separable_derivatives(plane)}) {
    INFO(report.summary());
    CHECK(report.comparisons > 0);
    CHECK(report.passed());
  }
  struct WrongGradU : nonsep::testing::VariableMass2D {
    void grad_U(std::span<const double> q, std::span<double> out, std::size_t count) const {
      VariableMass2D::grad_U(q, out, count);
      for (std::size_t b = 0; b < count; ++b) out[2 * b + 1] += 1e-4;
    }
  };
  const auto wrong = nonsep::check_separable_derivatives(WrongGradU{});
  CHECK_FALSE(wrong.passed());
  REQUIRE(!wrong.mismatches.empty());
  CHECK(wrong.mismatches.front().function == "grad_U");
  CHECK(wrong.mismatches.front().component == 1);
  const double x[4] = {0.4, -0.9, 0.7, -0.3};
  double g[2], h[4], k = 0.0, u = 0.0;
  plane.grad_T(std::span<const double>(x + 2, 2), g, 1);
  plane.hessian_V(std::span<const double>(x, 2), h, 1);
  plane.value_K(std::span<const double>(x + 2, 2), std::span<double>(&k, 1), 1);
  plane.value_U(std::span<const double>(x, 2), std::span<double>(&u, 1), 1);
  const double product = g[0] * (h[0] * g[0] + h[1] * g[1]) + g[1] * (h[2] * g[0] + h[3] * g[1]);
  CHECK(plane.hamiltonian(x) == doctest::Approx(product + k + u).epsilon(1e-14));
}

}  // namespace test_models
