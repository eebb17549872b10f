// The derivative checker passes correct derivatives and catches wrong ones (so its passes mean something).
#include <doctest/doctest.h>

#include "nonsep/derivative_checker.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "support/models.hpp"

namespace test_derivative_checker {

namespace {

// A correct model except for one deliberately wrong derivative, chosen by `wrong`.
struct Anharmonic2D {
  enum class Wrong { nothing, grad_V, hessian_T, d3V };
  static constexpr std::size_t dimension = 2;
  Wrong wrong = Wrong::nothing;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0 + nonsep::sdk::cube(p[1]) / 6.0 + p[0] * p[1];
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] * q[1] + q[1] * q[1] / 2.0;
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    out[0] = 2.0 * q[0] * q[1];
    out[1] = q[0] * q[0] + q[1] * (wrong == Wrong::grad_V ? 1.001 : 1.0);
  }
  void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    out[0] = 1.0;
    out[1] = out[2] = wrong == Wrong::hessian_T ? 0.0 : 1.0;
    out[3] = p[1];
  }
  // V_001 = 2, every other third derivative of V is 0: d3V = (4 u0 u1, 2 u0^2); d3T comes from automatic
  // differentiation.
  void d3V(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> u, std::span<double> out) const {
    out[0] = 4.0 * u[0] * u[1];
    out[1] = 2.0 * u[0] * u[0] + (wrong == Wrong::d3V ? 1e-3 : 0.0);
  }
};

using Adapter = nonsep::sdk::ModelAdapter<Anharmonic2D>;

Adapter with(Anharmonic2D::Wrong wrong) { return Adapter(Anharmonic2D{wrong}); }

}  // namespace

TEST_CASE("correct analytic and automatic derivatives pass") {
  const auto report = nonsep::check_derivatives(with(Anharmonic2D::Wrong::nothing));
  INFO(report.summary());
  CHECK(report.passed());
  CHECK(report.comparisons == 16 * (2 + 2 + 4 + 4 + 2 + 2 + 2 + 2));
  CHECK(report.largest_error < 1e-9);
  CHECK(report.skipped.empty());
}

TEST_CASE("a gradient off by 0.1 percent is caught and located") {
  // grad_V[1] disagrees with the differences of V, and (correct, automatic) Hess V[1][1] and hvp_V[1] with the
  // differences of the wrong grad_V[1]; nothing else is flagged.
  const auto report = nonsep::check_derivatives(with(Anharmonic2D::Wrong::grad_V));
  REQUIRE_FALSE(report.passed());
  std::size_t gradient_mismatches = 0;
  for (const auto& mismatch : report.mismatches) {
    CAPTURE(mismatch.function);
    CHECK(((mismatch.function == "grad_V" && mismatch.component == 1) ||
           (mismatch.function == "hessian_V" && mismatch.component == 3) ||
           (mismatch.function == "hvp_V" && mismatch.component == 1)));
    gradient_mismatches += mismatch.function == "grad_V";
  }
  CHECK(gradient_mismatches == 16);
}

TEST_CASE("a wrong off-diagonal Hessian entry is caught in both places") {
  const auto report = nonsep::check_derivatives(with(Anharmonic2D::Wrong::hessian_T));
  REQUIRE_FALSE(report.passed());
  for (const auto& mismatch : report.mismatches) {
    CHECK(mismatch.function == "hessian_T");
    CHECK((mismatch.component == 1 || mismatch.component == 2));
    CHECK(mismatch.finite_difference == doctest::Approx(1.0));
  }
}

TEST_CASE("a wrong directional third derivative is caught and located") {
  const auto report = nonsep::check_derivatives(with(Anharmonic2D::Wrong::d3V));
  REQUIRE_FALSE(report.passed());
  CHECK(report.mismatches.size() == 16);
  for (const auto& mismatch : report.mismatches) {
    CHECK(mismatch.function == "d3V");
    CHECK(mismatch.component == 1);
    CHECK(mismatch.computed - mismatch.finite_difference == doctest::Approx(1e-3).epsilon(1e-3));
  }
}

TEST_CASE("a model without values has its Hessians checked and the gradient check reported as skipped") {
  // Coupled2D with its value_T and value_V hidden.
  struct WithoutValues : private nonsep::testing::Coupled2D {
    using Coupled2D::dimension, Coupled2D::grad_T, Coupled2D::grad_V, Coupled2D::hessian_T, Coupled2D::hessian_V,
        Coupled2D::d3T, Coupled2D::d3V;
  };
  nonsep::DerivativeCheckOptions options;
  options.points = {{0.3, -0.2}};
  options.random_points = 2;
  const auto report = nonsep::check_derivatives(WithoutValues{}, options);
  INFO(report.summary());
  CHECK(report.passed());
  CHECK(report.comparisons == 3 * (4 + 4 + 2 + 2));
  REQUIRE(report.skipped.size() == 2);
  CHECK(report.skipped[0] == "gradients: the model has no value_T/value_V");
  CHECK(report.skipped[1] == "Hessian-vector products: the model has no hvp_T/hvp_V");
}

}  // namespace test_derivative_checker
