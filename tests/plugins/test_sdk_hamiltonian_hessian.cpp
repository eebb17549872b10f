// The SDK's derivatives of grad H (model_adapter.hpp): hvp_H forms its sums of third and fourth derivatives in three
// seeded passes, and grad H takes the inner product from the pass of the third derivatives. Checked for every kind
// of tangent (only dq, only dp, both, none) and both forms, with derivatives by duals over T and V, over gradient
// templates, and partly or wholly written out: against central differences of grad H, linear in the tangent, the
// written-out mixed third and fourth derivatives against the dual numbers' to round-off, and grad H bit for bit what
// the separate products give.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "lattice_chain/lattice_chain.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/plugin_sdk.hpp"
#include "paper1d/paper1d.hpp"
#include "paper2d/paper2d.hpp"
#include "support/random_points.hpp"

namespace test_sdk_hamiltonian_hessian {

using nonsep::HamiltonianForm;
using nonsep::sdk::Derivatives;
using nonsep::sdk::ModelAdapter;

using nonsep::testing::random_points;

namespace {

// Four states at one point (q, p) with the tangents (dq, 0), (0, dp), (dq, dp) and (0, 0): hvp_H against central
// differences of grad H, the third the sum of the first two, the fourth zero.
template <class Adapter>
void check_hamiltonian_hessian(const Adapter& model, HamiltonianForm form, unsigned seed) {
  const std::size_t n = model.dimension(), count = 4;
  const auto point_q = random_points(n, 0.8, seed), point_p = random_points(n, 0.8, seed + 1),
             tangent_q = random_points(n, 1.0, seed + 2), tangent_p = random_points(n, 1.0, seed + 3);
  std::vector<double> q, p, dq(count * n, 0.0), dp(count * n, 0.0);
  for (std::size_t b = 0; b < count; ++b) {
    q.insert(q.end(), point_q.begin(), point_q.end());
    p.insert(p.end(), point_p.begin(), point_p.end());
  }
  for (std::size_t i = 0; i < n; ++i) {
    dq[i] = dq[2 * n + i] = tangent_q[i];
    dp[n + i] = dp[2 * n + i] = tangent_p[i];
  }
  std::vector<double> out_q(count * n), out_p(count * n);
  model.hvp_H(form, q, p, dq, dp, out_q, out_p, count);

  const double h = 1e-5;
  std::vector<double> plus_q(count * n), plus_p(count * n), minus_q(count * n), minus_p(count * n);
  for (const int side : {1, -1}) {
    std::vector<double> at_q = q, at_p = p;
    for (std::size_t k = 0; k < count * n; ++k) {
      at_q[k] += side * h * dq[k];
      at_p[k] += side * h * dp[k];
    }
    nonsep::HamiltonianGradient(form).evaluate(model, at_q, at_p, side > 0 ? plus_q : minus_q,
                                               side > 0 ? plus_p : minus_p, count);
  }
  for (std::size_t k = 0; k < 3 * n; ++k) {
    CAPTURE(k);
    CHECK(out_q[k] == doctest::Approx((plus_q[k] - minus_q[k]) / (2 * h)).epsilon(1e-7));
    CHECK(out_p[k] == doctest::Approx((plus_p[k] - minus_p[k]) / (2 * h)).epsilon(1e-7));
  }
  for (std::size_t i = 0; i < n; ++i) {
    CAPTURE(i);
    const double sum_q = out_q[i] + out_q[n + i], sum_p = out_p[i] + out_p[n + i];
    CHECK(std::abs(out_q[2 * n + i] - sum_q) <= 1e-13 * std::max(1.0, std::abs(sum_q)));
    CHECK(std::abs(out_p[2 * n + i] - sum_p) <= 1e-13 * std::max(1.0, std::abs(sum_p)));
    CHECK(out_q[3 * n + i] == 0.0);
    CHECK(out_p[3 * n + i] == 0.0);
  }
}

template <class Adapter>
void check_every_form(const Adapter& model, const char* what) {
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(what);
    CAPTURE(form == HamiltonianForm::TTV);
    check_hamiltonian_hessian(model, form, 11);
    check_hamiltonian_hessian(model, form, 23);
  }
}

// grad H through the core (which takes d3V_with_product where the model has it) against the separate calls:
// g = grad T(p), w = Hess V(q) g, dH/dq = d3V(q, g), dH/dp = 2 Hess T(p) w in TTV; roles swapped in VVT.
template <class Adapter>
void check_gradient_bit_for_bit(const Adapter& model, const char* what) {
  static_assert(nonsep::ModelWithThirdAndProduct<Adapter>);
  const std::size_t n = model.dimension(), count = 7, size = count * n;
  const auto q = random_points(size, 1.0, 5), p = random_points(size, 1.0, 6);
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(what);
    CAPTURE(form == HamiltonianForm::TTV);
    std::vector<double> a_q(size), a_p(size), b_q(size), b_p(size), g(size), w(size);
    nonsep::HamiltonianGradient(form).evaluate(model, q, p, a_q, a_p, count);
    if (form == HamiltonianForm::TTV) {
      model.grad_T(p, g, count);
      model.hvp_V(q, g, w, count);
      model.d3V(q, g, b_q, count);
      model.hvp_T(p, w, b_p, count);
      for (double& x : b_p) x *= 2.0;
    } else {
      model.grad_V(q, g, count);
      model.hvp_T(p, g, w, count);
      model.d3T(p, g, b_p, count);
      model.hvp_V(q, w, b_q, count);
      for (double& x : b_q) x *= 2.0;
    }
    CHECK(std::memcmp(a_q.data(), b_q.data(), size * sizeof(double)) == 0);
    CHECK(std::memcmp(a_p.data(), b_p.data(), size * sizeof(double)) == 0);
  }
}

// paper2d with its gradients written as templates and nothing else written out: the SDK differentiates the gradients
// for every higher derivative (the lattice chain writes out its products, which grad H then takes instead).
struct Paper2DGradients {
  static constexpr std::size_t dimension = 2;
  static constexpr double coupling = 0.25;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] + p[1] + (p[0] * p[0] * p[0] + p[1] * p[1] * p[1]) / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S x2 = q[0] * q[0], y2 = q[1] * q[1], r2 = x2 + y2;
    return r2 / 2.0 + r2 * r2 / 12.0 + coupling * x2 * y2;
  }
  template <class S>
  void grad_T(nonsep::sdk::Vector<S> p, std::span<S> out) const {
    out[0] = 1.0 + 0.5 * p[0] * p[0];
    out[1] = 1.0 + 0.5 * p[1] * p[1];
  }
  template <class S>
  void grad_V(nonsep::sdk::Vector<S> q, std::span<S> out) const {
    const S radial = 1.0 + (q[0] * q[0] + q[1] * q[1]) / 3.0;
    out[0] = q[0] * radial + 2.0 * coupling * q[0] * q[1] * q[1];
    out[1] = q[1] * radial + 2.0 * coupling * q[0] * q[0] * q[1];
  }
};

// hvp_H of a model that writes out d3T, d3V (mixed), d4T and d4V against the same model differentiated by dual
// numbers, at random points and tangents of every kind, both forms: the same numbers to round-off.
template <class M>
void check_written_out_fourth(const char* parameters, const char* what) {
  const auto written = ModelAdapter<M>::from_json(parameters);
  const auto automatic = ModelAdapter<M, Derivatives::automatic>::from_json(parameters);
  static_assert(ModelAdapter<M>::analytic_mixed_T && ModelAdapter<M>::analytic_mixed_V);
  static_assert(!decltype(automatic)::analytic_mixed_T && !decltype(automatic)::analytic_mixed_V);
  const std::size_t n = written.dimension(), count = 24, size = count * n;
  const auto q = random_points(size, 1.5, 31), p = random_points(size, 1.5, 32);
  auto dq = random_points(size, 1.0, 33), dp = random_points(size, 1.0, 34);
  for (std::size_t b = 0; b < count; ++b)  // every third state without dq, every third from the second without dp
    for (std::size_t i = 0; i < n; ++i) {
      if (b % 3 == 0) dq[b * n + i] = 0.0;
      if (b % 3 == 1) dp[b * n + i] = 0.0;
    }
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(what);
    CAPTURE(form == HamiltonianForm::TTV);
    std::vector<double> a_q(size), a_p(size), b_q(size), b_p(size);
    written.hvp_H(form, q, p, dq, dp, a_q, a_p, count);
    automatic.hvp_H(form, q, p, dq, dp, b_q, b_p, count);
    for (std::size_t k = 0; k < size; ++k) {
      CAPTURE(k);
      CHECK(std::abs(a_q[k] - b_q[k]) <= 1e-14 * std::max(1.0, std::abs(b_q[k])) * 8);
      CHECK(std::abs(a_p[k] - b_p[k]) <= 1e-14 * std::max(1.0, std::abs(b_p[k])) * 8);
    }
  }
}

// A batch whose states share points in runs (as Gauss's tangent map asks: 2n directions per stage point), broken by
// other points and zero tangents: each state's hvp_H bit for bit what a call for it alone gives.
template <class Adapter>
void check_batch_equals_single(const Adapter& model, const char* what) {
  const std::size_t n = model.dimension();
  const auto a_q = random_points(n, 0.8, 41), a_p = random_points(n, 0.8, 42), b_q = random_points(n, 0.8, 43),
             b_p = random_points(n, 0.8, 44);
  const int at[] = {0, 0, 0, 1, 1, 0, 0, 0, 1};  // point A or B per state
  const std::size_t count = std::size(at);
  std::vector<double> q, p;
  for (const int point : at) {
    q.insert(q.end(), (point ? b_q : a_q).begin(), (point ? b_q : a_q).end());
    p.insert(p.end(), (point ? b_p : a_p).begin(), (point ? b_p : a_p).end());
  }
  auto dq = random_points(count * n, 1.0, 45), dp = random_points(count * n, 1.0, 46);
  for (std::size_t i = 0; i < n; ++i) {
    dq[1 * n + i] = 0.0;                  // dp only
    dp[2 * n + i] = 0.0;                  // dq only
    dq[6 * n + i] = dp[6 * n + i] = 0.0;  // none, between two states at A
    dq[7 * n + i] = 0.0;
  }
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(what);
    CAPTURE(form == HamiltonianForm::TTV);
    std::vector<double> out_q(count * n), out_p(count * n);
    model.hvp_H(form, q, p, dq, dp, out_q, out_p, count);
    for (std::size_t b = 0; b < count; ++b) {
      CAPTURE(b);
      const auto part = [&](const std::vector<double>& v) {
        return std::vector<double>(v.begin() + static_cast<std::ptrdiff_t>(b * n),
                                   v.begin() + static_cast<std::ptrdiff_t>((b + 1) * n));
      };
      std::vector<double> alone_q(n), alone_p(n);
      model.hvp_H(form, part(q), part(p), part(dq), part(dp), alone_q, alone_p, 1);
      CHECK(std::memcmp(alone_q.data(), out_q.data() + b * n, n * sizeof(double)) == 0);
      CHECK(std::memcmp(alone_p.data(), out_p.data() + b * n, n * sizeof(double)) == 0);
    }
  }
}

using Lattice = LatticeChainModel<16>;
const char* const lattice_parameters = R"({"sites": 5, "kinetic_quartic": 0.7, "coupling": 0.4, "bond_quartic": 1.3})";

}  // namespace

TEST_CASE("SDK hvp_H: every kind of tangent, both forms, against differences of grad H (duals, gradient templates)") {
  check_every_form(ModelAdapter<Lattice>::from_json(lattice_parameters),
                   "lattice chain, gradient templates and written-out products");
  check_every_form(ModelAdapter<Paper2DGradients>(), "paper2d, gradient templates");
  check_every_form(ModelAdapter<Lattice, Derivatives::automatic>::from_json(lattice_parameters),
                   "lattice chain, duals over T and V");
  check_every_form(ModelAdapter<Paper2D>::from_json(R"({"coupling": 0.25})"), "paper2d, every derivative written out");
  check_every_form(ModelAdapter<Paper2D, Derivatives::automatic>::from_json(R"({"coupling": 0.25})"),
                   "paper2d, duals over T and V");
}

TEST_CASE("SDK hvp_H: written-out mixed third and fourth derivatives give the dual numbers' products to round-off") {
  check_written_out_fourth<Paper1D>("{}", "paper1d");
  check_written_out_fourth<Paper2D>(R"({"coupling": 0.25})", "paper2d");
  check_written_out_fourth<Paper2D>(R"({"coupling": -0.1})", "paper2d, negative coupling");
}

TEST_CASE("SDK hvp_H: states at one point in a row give each state's numbers alone, bit for bit") {
  check_batch_equals_single(ModelAdapter<Paper2D>::from_json(R"({"coupling": 0.25})"), "paper2d, written out");
  check_batch_equals_single(ModelAdapter<Paper2D, Derivatives::automatic>::from_json(R"({"coupling": 0.25})"),
                            "paper2d, duals over T and V");
  check_batch_equals_single(ModelAdapter<Paper2DGradients>(), "paper2d, gradient templates");
  check_batch_equals_single(ModelAdapter<Lattice>::from_json(lattice_parameters), "lattice chain");
}

TEST_CASE("SDK grad H: the inner product taken from the pass of the third derivatives is bit for bit the product's") {
  check_gradient_bit_for_bit(ModelAdapter<Paper2DGradients>(), "paper2d, gradient templates");
  check_gradient_bit_for_bit(ModelAdapter<Lattice, Derivatives::automatic>::from_json(lattice_parameters),
                             "lattice chain, duals over T and V");
  check_gradient_bit_for_bit(ModelAdapter<Paper2D, Derivatives::automatic>::from_json(R"({"coupling": 0.25})"),
                             "paper2d, duals over T and V");
  // A model that writes out its products (or d3V) keeps them: no combined pass.
  static_assert(!nonsep::ModelWithThirdAndProduct<ModelAdapter<Paper2D>>);
  static_assert(!nonsep::ModelWithThirdAndProduct<ModelAdapter<Lattice>>);
}

}  // namespace test_sdk_hamiltonian_hessian
