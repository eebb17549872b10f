// Hessian-vector products at the plugin boundary (hvp_T, hvp_V) and the lattice chain, whose gradients are
// templates the SDK differentiates: every shipped plugin's products equal its dense Hessian times v; the derivative
// checker differences them from the gradients; differentiating the lattice's gradient templates gives what
// differentiating its T and V gives; its products at n = 10^5 are the tridiagonal closed form; its energy is
// sum_ij T_i V_ij T_j, and its written-out energy (energy_TTV, energy_VVT) is H from the dense Hessians.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "lattice_chain/lattice_chain.hpp"
#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"
#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "support/random_points.hpp"

namespace test_hessian_vector_products {

using nonsep::host::load_plugin;
using nonsep::host::PluginModel;
using nonsep::sdk::Derivatives;
using nonsep::sdk::ModelAdapter;

using nonsep::testing::random_points;

namespace {

PluginModel shipped(const std::string& name, const nlohmann::json& parameters = nlohmann::json::object()) {
  return load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/" + name + ".so", "").create(parameters);
}

// |a - b| <= tolerance max(1, |b|) for every entry.
void check_agree(const std::vector<double>& a, const std::vector<double>& b, double tolerance, const char* what) {
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    CAPTURE(what);
    CAPTURE(k);
    CHECK(std::abs(a[k] - b[k]) <= tolerance * std::max(1.0, std::abs(b[k])));
  }
}

// out_b = H_b v_b for `count` row-major n x n matrices.
std::vector<double> times(const std::vector<double>& hessians, const std::vector<double>& v, std::size_t n,
                          std::size_t count) {
  std::vector<double> out(count * n, 0.0);
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) out[b * n + i] += hessians[(b * n + i) * n + j] * v[b * n + j];
  return out;
}

const std::pair<const char*, nlohmann::json> shipped_plugins[] = {
    {"paper1d", nlohmann::json::object()},     {"radial", {{"dimension", 5}}},
    {"quadratic_kinetic", {{"lambda", -1.5}}}, {"tao_product", nlohmann::json::object()},
    {"paper2d", {{"coupling", -0.1}}},         {"lattice_chain", {{"sites", 7}}}};

}  // namespace

TEST_CASE("every shipped plugin's Hessian-vector products are its dense Hessians times v, in one batched call") {
  for (const auto& [name, parameters] : shipped_plugins) {
    const std::string plugin_name(name);  // clang 14 cannot capture a structured binding
    CAPTURE(plugin_name);
    const PluginModel model = shipped(name, parameters);
    REQUIRE(model.plugin().has_hessian_vector_products());
    // The lattice, paper1d, paper2d and tao_product write their products out (test_shipped_models.cpp compares
    // the three's with automatic differentiation, the next test the lattice's); the others' are automatic.
    const bool written = plugin_name == "lattice_chain" || plugin_name == "paper1d" || plugin_name == "paper2d" ||
                         plugin_name == "tao_product";
    const char* kind = written ? "analytic" : "automatic";
    CHECK(model.plugin().metadata()["derivatives"]["hvp_T"] == kind);
    CHECK(model.plugin().metadata()["derivatives"]["hvp_V"] == kind);
    const std::size_t n = model.dimension(), count = 9;
    const auto x = random_points(count * n, 1.5, 3), v = random_points(count * n, 1.0, 5);
    std::vector<double> hessians(count * n * n), products(count * n);
    model.hessian_T(x, hessians, count);
    model.hvp_T(x, v, products, count);
    check_agree(products, times(hessians, v, n, count), 1e-12, "hvp_T");
    model.hessian_V(x, hessians, count);
    model.hvp_V(x, v, products, count);
    check_agree(products, times(hessians, v, n, count), 1e-12, "hvp_V");
  }
}

TEST_CASE("the derivative checker differences Hessian-vector products from the gradients, and finds a wrong one") {
  for (const auto& [name, parameters] : shipped_plugins) {
    const std::string plugin_name(name);  // clang 14 cannot capture a structured binding
    CAPTURE(plugin_name);
    const auto report = nonsep::check_derivatives(shipped(name, parameters));
    INFO(report.summary());
    CHECK(report.passed());
    CHECK(report.skipped.empty());
  }
  // A model whose hvp_V is off by 1e-4 in one component.
  struct Wrong : ModelAdapter<LatticeChainModel<16>> {
    using ModelAdapter::ModelAdapter;
    void hvp_V(std::span<const double> q, std::span<const double> v, std::span<double> out, std::size_t count) const {
      ModelAdapter::hvp_V(q, v, out, count);
      out[2] += 1e-4;
    }
  };
  const Wrong wrong(nonsep::sdk::parse_parameters(nonsep::sdk::parameter_table<LatticeChainModel<16>>(), "{}"));
  const auto report = nonsep::check_derivatives(wrong);
  REQUIRE_FALSE(report.passed());
  CHECK(report.mismatches.front().function == "hvp_V");
  CHECK(report.mismatches.front().component == 2);
}

TEST_CASE(
    "lattice chain: its written-out products and differentiated gradient templates give what differentiating T and V "
    "gives") {
  const std::string parameters = R"({"sites": 9, "kinetic_quartic": 0.7, "coupling": 0.4, "bond_quartic": 1.3})";
  using Model = LatticeChainModel<16>;
  const auto of_gradients = ModelAdapter<Model>::from_json(parameters);
  const auto of_functions = ModelAdapter<Model, Derivatives::automatic>::from_json(parameters);
  static_assert(ModelAdapter<Model>::differentiates_gradients && !decltype(of_functions)::differentiates_gradients);
  const std::size_t n = 9, count = 16;
  const auto x = random_points(count * n, 2.0, 7), u = random_points(count * n, 1.0, 9);
  std::vector<double> a(count * n), b(count * n), ha(count * n * n), hb(count * n * n);
  for (const bool kinetic : {true, false}) {
    CAPTURE(kinetic);
    (kinetic ? of_gradients.grad_T(x, a, count) : of_gradients.grad_V(x, a, count));
    (kinetic ? of_functions.grad_T(x, b, count) : of_functions.grad_V(x, b, count));
    check_agree(a, b, 1e-13, "gradient");
    (kinetic ? of_gradients.hessian_T(x, ha, count) : of_gradients.hessian_V(x, ha, count));
    (kinetic ? of_functions.hessian_T(x, hb, count) : of_functions.hessian_V(x, hb, count));
    check_agree(ha, hb, 1e-13, "Hessian");
    (kinetic ? of_gradients.hvp_T(x, u, a, count) : of_gradients.hvp_V(x, u, a, count));
    (kinetic ? of_functions.hvp_T(x, u, b, count) : of_functions.hvp_V(x, u, b, count));
    check_agree(a, b, 1e-13, "Hessian-vector product");
    (kinetic ? of_gradients.d3T(x, u, a, count) : of_gradients.d3V(x, u, a, count));
    (kinetic ? of_functions.d3T(x, u, b, count) : of_functions.d3V(x, u, b, count));
    check_agree(a, b, 1e-12, "third derivative");
  }
}

TEST_CASE("lattice chain at n = 10^5: Hessian-vector products are the tridiagonal closed form") {
  const std::size_t n = 100000;
  const double a = 0.7, k = 0.4, b = 1.3;
  const PluginModel model =
      shipped("lattice_chain", {{"sites", n}, {"kinetic_quartic", a}, {"coupling", k}, {"bond_quartic", b}});
  const auto x = random_points(n, 1.5, 11), v = random_points(n, 1.0, 13);
  std::vector<double> product(n), expected(n);
  model.hvp_T(x, v, product, 1);
  for (std::size_t i = 0; i < n; ++i) expected[i] = (1.0 + a * x[i] * x[i]) * v[i];
  check_agree(product, expected, 1e-14, "hvp_T");
  // W''(r) = k + 3 b r^2 on bond i (sites i, i+1).
  auto stiffness = [&](std::size_t i) {
    const double r = x[(i + 1) % n] - x[i];
    return k + 3.0 * b * r * r;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t left = (i + n - 1) % n, right = (i + 1) % n;
    expected[i] = (1.0 + stiffness(i) + stiffness(left)) * v[i] - stiffness(i) * v[right] - stiffness(left) * v[left];
  }
  model.hvp_V(x, v, product, 1);
  check_agree(product, expected, 1e-13, "hvp_V");
}

TEST_CASE("lattice chain: the energy is sum_ij T_i V_ij T_j, T_i = p_i + a p_i^3/3, V_ij tridiagonal") {
  const std::size_t n = 6, count = 8;
  const double a = 1.0, k = 0.5, b = 1.0;
  const PluginModel model = shipped("lattice_chain", {{"sites", n}});
  nonsep::PhaseSpaceBatch x(n, count);
  const auto q = random_points(count * n, 1.5, 17), p = random_points(count * n, 1.5, 19);
  std::copy(q.begin(), q.end(), x.q().begin());
  std::copy(p.begin(), p.end(), x.p().begin());
  std::vector<double> energies(count);
  nonsep::EnergyEvaluator(nonsep::HamiltonianForm::TTV).evaluate(model, x, energies);
  for (std::size_t s = 0; s < count; ++s) {
    const auto qs = x.q(s), ps = x.p(s);
    double h = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const double ti = ps[i] + a * ps[i] * ps[i] * ps[i] / 3, tj = ps[j] + a * ps[j] * ps[j] * ps[j] / 3;
      const double r = qs[j] - qs[i], w2 = k + 3 * b * r * r;
      h += ti * ti + w2 * (ti - tj) * (ti - tj);
    }
    CAPTURE(s);
    CHECK(energies[s] == doctest::Approx(h).epsilon(1e-13));
  }
}

namespace {

// A model forwarding to `Base`, with its Hessian-vector products (has_products) or without them, so that the core
// takes the dense path; its Hessians throw when `dense_forbidden`.
template <class Base, bool has_products>
struct Forwarding {
  const Base& base;
  bool dense_forbidden = false;
  std::size_t dimension() const { return base.dimension(); }
  void grad_T(std::span<const double> x, std::span<double> out, std::size_t count) const { base.grad_T(x, out, count); }
  void grad_V(std::span<const double> x, std::span<double> out, std::size_t count) const { base.grad_V(x, out, count); }
  void hessian_T(std::span<const double> x, std::span<double> out, std::size_t count) const {
    if (dense_forbidden) throw std::logic_error("hessian_T called");
    base.hessian_T(x, out, count);
  }
  void hessian_V(std::span<const double> x, std::span<double> out, std::size_t count) const {
    if (dense_forbidden) throw std::logic_error("hessian_V called");
    base.hessian_V(x, out, count);
  }
  void d3T(std::span<const double> x, std::span<const double> u, std::span<double> out, std::size_t count) const {
    base.d3T(x, u, out, count);
  }
  void d3V(std::span<const double> x, std::span<const double> u, std::span<double> out, std::size_t count) const {
    base.d3V(x, u, out, count);
  }
  void hvp_T(std::span<const double> x, std::span<const double> v, std::span<double> out,
             std::size_t count) const requires has_products {
    base.hvp_T(x, v, out, count);
  }
  void hvp_V(std::span<const double> x, std::span<const double> v, std::span<double> out,
             std::size_t count) const requires has_products {
    base.hvp_V(x, v, out, count);
  }
};

}  // namespace

TEST_CASE("the energy and the gradient of H through products equal the dense ones, and form no Hessian") {
  const PluginModel lattice = shipped("lattice_chain", {{"sites", 11}});
  const PluginModel paper2d = shipped("paper2d", {{"coupling", 0.2}});
  for (const PluginModel* model : {&lattice, &paper2d}) {
    CAPTURE(model->plugin().name());
    const Forwarding<PluginModel, true> products{*model, true};
    const Forwarding<PluginModel, false> dense{*model};
    static_assert(nonsep::ModelWithHessianProducts<Forwarding<PluginModel, true>> &&
                  !nonsep::ModelWithHessianProducts<Forwarding<PluginModel, false>>);
    const std::size_t n = model->dimension(), count = 12;
    nonsep::PhaseSpaceBatch x(n, count);
    const auto q = random_points(count * n, 1.5, 23), p = random_points(count * n, 1.5, 29);
    std::copy(q.begin(), q.end(), x.q().begin());
    std::copy(p.begin(), p.end(), x.p().begin());
    for (const auto form : {nonsep::HamiltonianForm::TTV, nonsep::HamiltonianForm::VVT}) {
      CAPTURE(form == nonsep::HamiltonianForm::TTV);
      std::vector<double> by_products(count), by_matrices(count);
      nonsep::EnergyEvaluator(form).evaluate(products, x, by_products);
      nonsep::EnergyEvaluator(form).evaluate(dense, x, by_matrices);
      check_agree(by_products, by_matrices, 1e-13, "H");
      std::vector<double> dq(count * n), dp(count * n), dense_dq(count * n), dense_dp(count * n);
      nonsep::HamiltonianGradient gradient(form), dense_gradient(form);
      gradient.evaluate(products, x.q(), x.p(), dq, dp, count);
      dense_gradient.evaluate(dense, x.q(), x.p(), dense_dq, dense_dp, count);
      check_agree(dq, dense_dq, 1e-12, "dH/dq");
      check_agree(dp, dense_dp, 1e-12, "dH/dp");
      CHECK(gradient.evaluations().grad_H == count);
    }
  }
}

TEST_CASE("lattice chain: its written-out energy_TTV and energy_VVT are H from dense Hessians of T and V by AD") {
  // The reference: the adapter that differentiates T and V (no written-out derivative, no product energy) behind a
  // model without products, so that the core forms the n x n Hessians.
  using Model = LatticeChainModel<16>;
  static_assert(nonsep::ModelWithProductEnergy<ModelAdapter<Model>>);
  static_assert(!nonsep::ModelWithProductEnergy<ModelAdapter<Model, Derivatives::automatic>>);
  // n = 3, 5, 6 and 9: the sites between the two ends in the partial sums' four lanes, in the remainder, or both.
  for (const std::size_t n : {3, 5, 6, 9}) {
    CAPTURE(n);
    const std::string parameters =
        R"({"kinetic_quartic": 0.7, "coupling": 0.4, "bond_quartic": 1.3, "sites": )" + std::to_string(n) + "}";
    const auto sized = ModelAdapter<Model>::from_json(parameters);
    const auto sized_automatic = ModelAdapter<Model, Derivatives::automatic>::from_json(parameters);
    const Forwarding<decltype(sized_automatic), false> sized_dense{sized_automatic};
    const std::size_t count = 37;
    nonsep::PhaseSpaceBatch x(n, count);
    const auto q = random_points(count * n, 1.5, 31), p = random_points(count * n, 1.5, 37);
    std::copy(q.begin(), q.end(), x.q().begin());
    std::copy(p.begin(), p.end(), x.p().begin());
    for (const auto form : {nonsep::HamiltonianForm::TTV, nonsep::HamiltonianForm::VVT}) {
      CAPTURE(form == nonsep::HamiltonianForm::TTV);
      CHECK(sized.has_product_energy(form));
      std::vector<double> own(count), reference(count), direct(count);
      nonsep::EnergyEvaluator(form).evaluate(sized, x, own);
      nonsep::EnergyEvaluator(form).evaluate(sized_dense, x, reference);
      sized.product_energy(form, x.q(), x.p(), direct, count);
      check_agree(own, reference, 1e-13, "H");
      CHECK(own == direct);
    }
  }
}

TEST_CASE("lattice chain at n = 10^5 through the plugin: its own H equals H through the products, in both forms") {
  const std::size_t n = 100000;
  const PluginModel model = shipped("lattice_chain", {{"sites", n}, {"kinetic_quartic", 0.7}});
  nonsep::PhaseSpaceBatch x(n, 2);
  const auto q = random_points(2 * n, 1.5, 41), p = random_points(2 * n, 1.5, 43);
  std::copy(q.begin(), q.end(), x.q().begin());
  std::copy(p.begin(), p.end(), x.p().begin());
  for (const auto form : {nonsep::HamiltonianForm::TTV, nonsep::HamiltonianForm::VVT}) {
    CAPTURE(form == nonsep::HamiltonianForm::TTV);
    CHECK(model.has_product_energy(form));
    CHECK_FALSE(model.without_product_energy().has_product_energy(form));
    std::vector<double> own(2), by_products(2);
    nonsep::EnergyEvaluator(form).evaluate(model, x, own);
    nonsep::EnergyEvaluator(form).evaluate(model.without_product_energy(), x, by_products);
    check_agree(own, by_products, 1e-12, "H");
    CHECK(own[0] != by_products[0]);  // not the same path: the sums run in another order
  }
  // A model that does not write it out says so.
  CHECK_FALSE(shipped("paper2d").has_product_energy(nonsep::HamiltonianForm::TTV));
}

TEST_CASE("lattice chain: MPE 4 converges to Runge-Kutta-Fehlberg 7(8) on the closed-form Hamilton's equations") {
  // H = sum_i t_i^2 + sum_bonds W''(r) (t_{i+1} - t_i)^2, t_i = f'(p_i), W''(r) = k + 3 b r^2, r = q_{i+1} - q_i.
  const std::size_t n = 5;
  const double a = 1.0, k = 0.5, b = 1.0, t_end = 0.5;
  auto rhs = [&](const std::vector<double>& s, std::vector<double>& d) {
    const double* q = s.data();
    const double* p = s.data() + n;
    std::vector<double> t(n), dH_dt(n, 0.0), dH_dq(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) t[i] = p[i] + a * p[i] * p[i] * p[i] / 3;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t j = (i + 1) % n;
      const double r = q[j] - q[i], dt = t[j] - t[i];
      dH_dt[i] += 2 * t[i] - 2 * (k + 3 * b * r * r) * dt;
      dH_dt[j] += 2 * (k + 3 * b * r * r) * dt;
      dH_dq[j] += 6 * b * r * dt * dt;
      dH_dq[i] -= 6 * b * r * dt * dt;
    }
    for (std::size_t i = 0; i < n; ++i) {
      d[i] = dH_dt[i] * (1 + a * p[i] * p[i]);
      d[n + i] = -dH_dq[i];
    }
  };
  const std::vector<double> q0 = {0.3, -0.2, 0.5, 0.1, -0.4}, p0 = {0.4, 0.1, -0.3, 0.2, 0.6};
  std::vector<double> start = q0;
  start.insert(start.end(), p0.begin(), p0.end());
  const auto reference = nonsep::reference::hamiltonian_flow(rhs, start, t_end);
  const PluginModel model = shipped("lattice_chain", {{"sites", n}});
  std::vector<double> errors;
  for (const int steps : {400, 800}) {
    auto x = nonsep::PhaseSpaceBatch::single(q0, p0);
    nonsep::MultiProductExpansion<> mpe(nonsep::ChinBasicStep(), 6);
    for (int s = 0; s < steps; ++s) mpe.step(model, x, t_end / steps);
    double error = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      error = std::max({error, std::abs(x.q()[i] - reference[i]), std::abs(x.p()[i] - reference[n + i])});
    errors.push_back(error);
  }
  CAPTURE(errors[0]);
  CAPTURE(errors[1]);
  // Still approaching order 4 here: error ratios 7.5, 10.8, 13.4 for 100 -> 200 -> 400 -> 800 steps.
  CHECK(std::abs(std::log2(errors[0] / errors[1]) - 4.0) < 0.4);
  CHECK(errors[1] < 3e-7);
}

TEST_CASE("tangent vectors through products follow the dense tangent map, without a Hessian") {
  const PluginModel model = shipped("lattice_chain", {{"sites", 6}});
  const Forwarding<PluginModel, true> products{model, true};
  const Forwarding<PluginModel, false> dense{model};
  const std::size_t n = 6, count = 2;
  for (const std::size_t k : {std::size_t{1}, std::size_t{3}}) {
    CAPTURE(k);
    nonsep::PhaseSpaceBatch x(n, count), tangents(n, count * k);
    const auto q = random_points(count * n, 0.5, 31), p = random_points(count * n, 0.5, 37);
    std::copy(q.begin(), q.end(), x.q().begin());
    std::copy(p.begin(), p.end(), x.p().begin());
    const auto dq = random_points(count * k * n, 1.0, 41), dp = random_points(count * k * n, 1.0, 43);
    std::copy(dq.begin(), dq.end(), tangents.q().begin());
    std::copy(dp.begin(), dp.end(), tangents.p().begin());
    auto x_dense = x, tangents_dense = tangents;
    nonsep::TangentBasicStep by_products, by_matrices;
    for (int s = 0; s < 20; ++s) {
      by_products.step(products, x, tangents, 0.002);
      by_matrices.step(dense, x_dense, tangents_dense, 0.002);
    }
    CHECK(x == x_dense);
    const std::vector<double> a(tangents.q().begin(), tangents.q().end()),
        b(tangents_dense.q().begin(), tangents_dense.q().end()), c(tangents.p().begin(), tangents.p().end()),
        d(tangents_dense.p().begin(), tangents_dense.p().end());
    check_agree(a, b, 1e-12, "dq");
    check_agree(c, d, 1e-12, "dp");
    CHECK(by_products.hessian_evaluations() == nonsep::HessianCounts{});
  }
}

}  // namespace test_hessian_vector_products
