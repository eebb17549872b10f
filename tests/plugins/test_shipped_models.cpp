// The shipped models, loaded as plugins: they pass the derivative checker (third derivatives included, and hvp_H),
// their automatic and analytic derivatives agree to 1e-12, the energy the core computes from them is the Hamiltonian
// each documents, its gradient is what plugin_abi.h says the third derivatives give, and a plugin steps exactly like
// the same model compiled in.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mathews_lakshmanan/mathews_lakshmanan.hpp"
#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"
#include "paper1d/paper1d.hpp"
#include "paper2d/paper2d.hpp"
#include "quadratic_kinetic/quadratic_kinetic.hpp"
#include "radial/radial.hpp"
#include "tao_product/tao_product.hpp"

namespace test_shipped_models {

using nonsep::host::load_plugin;
using nonsep::host::PluginModel;
using nonsep::sdk::Derivatives;
using nonsep::sdk::ModelAdapter;

namespace {

PluginModel shipped(const std::string& name, const nlohmann::json& parameters = nlohmann::json::object()) {
  return load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/" + name + ".so", "").create(parameters);
}

std::vector<double> random_points(std::size_t count, std::size_t n, double box, unsigned seed) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> uniform(-box, box);
  std::vector<double> x(count * n);
  for (double& xi : x) xi = uniform(engine);
  return x;
}

// |a - b| <= 1e-12 max(1, |b|) for every entry.
void check_agree(const std::vector<double>& a, const std::vector<double>& b, const char* what) {
  REQUIRE(a.size() == b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    CAPTURE(what);
    CAPTURE(k);
    CHECK(std::abs(a[k] - b[k]) <= 1e-12 * std::max(1.0, std::abs(b[k])));
  }
}

// Automatic versus analytic (preferred) derivatives of model class M at 64 random points per variable.
template <class M>
void check_automatic_matches_analytic(const std::string& parameters = "{}") {
  const auto automatic = ModelAdapter<M, Derivatives::automatic>::from_json(parameters);
  const auto analytic = ModelAdapter<M, Derivatives::preferred>::from_json(parameters);
  static_assert(ModelAdapter<M>::analytic_grad_T && ModelAdapter<M>::analytic_grad_V,
                "every shipped model has analytic gradients");
  const std::size_t n = automatic.dimension(), count = 64;
  const auto x = random_points(count, n, 2.0, 7);
  std::vector<double> a(n * count), b(n * count), ha(n * n * count), hb(n * n * count);
  // Each function of both adapters into out_a, out_b, compared.
  const auto same = [&](const char* what, std::vector<double>& out_a, std::vector<double>& out_b,
                        const auto& evaluate) {
    evaluate(automatic, out_a);
    evaluate(analytic, out_b);
    check_agree(out_a, out_b, what);
  };
  same("grad_T", a, b, [&](const auto& m, auto& out) { m.grad_T(x, out, count); });
  same("grad_V", a, b, [&](const auto& m, auto& out) { m.grad_V(x, out, count); });
  same("hessian_T", ha, hb, [&](const auto& m, auto& out) { m.hessian_T(x, out, count); });
  same("hessian_V", ha, hb, [&](const auto& m, auto& out) { m.hessian_V(x, out, count); });
  // Hessian-vector products and directional third derivatives, along random directions.
  const auto u = random_points(count, n, 1.5, 9);
  same("hvp_T", a, b, [&](const auto& m, auto& out) { m.hvp_T(x, u, out, count); });
  same("hvp_V", a, b, [&](const auto& m, auto& out) { m.hvp_V(x, u, out, count); });
  same("d3T", a, b, [&](const auto& m, auto& out) { m.d3T(x, u, out, count); });
  same("d3V", a, b, [&](const auto& m, auto& out) { m.d3V(x, u, out, count); });
}

// H_TTV from the core's EnergyEvaluator (grad T . Hess V grad T) against the closed form, at random states.
template <class ClosedForm>
void check_energy(const PluginModel& model, const ClosedForm& expected) {
  const std::size_t n = model.dimension(), count = 32;
  nonsep::PhaseSpaceBatch x(n, count);
  const auto q = random_points(count, n, 1.8, 11), p = random_points(count, n, 1.8, 13);
  std::copy(q.begin(), q.end(), x.q().begin());
  std::copy(p.begin(), p.end(), x.p().begin());
  std::vector<double> energies(count);
  nonsep::EnergyEvaluator(nonsep::HamiltonianForm::TTV).evaluate(model, x, energies);
  for (std::size_t b = 0; b < count; ++b) {
    CAPTURE(b);
    CHECK(energies[b] == doctest::Approx(expected(x.q(b), x.p(b))).epsilon(1e-13));
  }
}

double squared_norm(std::span<const double> x) {
  double sum = 0.0;
  for (double xi : x) sum += xi * xi;
  return sum;
}

}  // namespace

TEST_CASE("automatic and analytic derivatives of the shipped models agree to 1e-12") {
  SUBCASE("paper1d") { check_automatic_matches_analytic<Paper1D>(); }
  SUBCASE("radial, dimension 1") { check_automatic_matches_analytic<Radial>(R"({"dimension": 1})"); }
  SUBCASE("radial, dimension 3") { check_automatic_matches_analytic<Radial>(R"({"dimension": 3})"); }
  SUBCASE("radial, dimension 16") { check_automatic_matches_analytic<Radial>(R"({"dimension": 16})"); }
  SUBCASE("quadratic_kinetic") { check_automatic_matches_analytic<QuadraticKinetic>(R"({"lambda": 0.7})"); }
  SUBCASE("tao_product") { check_automatic_matches_analytic<TaoProduct>(); }
  SUBCASE("mathews_lakshmanan") {
    check_automatic_matches_analytic<MathewsLakshmanan>(R"({"lambda": 0.8, "alpha": 1.3})");
  }
  SUBCASE("paper2d") { check_automatic_matches_analytic<Paper2D>(R"({"coupling": 0.3})"); }
}

TEST_CASE("every shipped plugin passes the derivative checker") {
  const std::pair<const char*, nlohmann::json> plugins[] = {{"paper1d", nlohmann::json::object()},
                                                            {"radial", {{"dimension", 2}}},
                                                            {"radial", {{"dimension", 5}}},
                                                            {"quadratic_kinetic", {{"lambda", -1.5}}},
                                                            {"tao_product", nlohmann::json::object()},
                                                            {"paper2d", {{"coupling", -0.1}}}};
  for (const auto& [name, parameters] : plugins) {
    const std::string plugin_name(name);  // clang 14 cannot capture a structured binding
    CAPTURE(plugin_name);
    const PluginModel model = shipped(name, parameters);
    CHECK(model.plugin().has_values());
    CHECK(model.plugin().has_hessians());
    CHECK(model.plugin().has_third_derivatives());
    CHECK(model.plugin().thread_safe());
    const auto report = nonsep::check_derivatives(model);
    INFO(report.summary());
    CHECK(report.passed());
    CHECK(report.skipped.empty());
    CHECK(report.comparisons > 0);
  }
}

TEST_CASE("each shipped model documents T, V and the Hamiltonian it solves") {
  for (const char* name : {"paper1d", "radial", "quadratic_kinetic", "tao_product", "paper2d", "lattice_chain"}) {
    const std::string plugin_name(name);  // clang 14 cannot capture a structured binding
    CAPTURE(plugin_name);
    const auto plugin = load_plugin(name, "");
    CHECK(plugin.name() == name);
    const std::string hamiltonian = plugin.metadata()["hamiltonian"].get<std::string>();
    CHECK(hamiltonian.find("T = ") != std::string::npos);
    CHECK(hamiltonian.find("V = ") != std::string::npos);
    CHECK(hamiltonian.find("H_TTV = ") != std::string::npos);
    CHECK(plugin.metadata()["derivatives"]["grad_T"] == "analytic");
  }
  // hvp_H from the written-out mixed third and fourth derivatives where the model has them, else by dual numbers.
  CHECK(load_plugin("paper1d", "").metadata()["derivatives"]["hvp_H"] == "analytic");
  CHECK(load_plugin("paper2d", "").metadata()["derivatives"]["hvp_H"] == "analytic");
  CHECK(load_plugin("radial", "").metadata()["derivatives"]["hvp_H"] == "automatic");
}

TEST_CASE("the energy of each shipped model is the Hamiltonian it documents") {
  SUBCASE("paper1d: (1 + p^2/2)^2 (1 + q^2)") {
    check_energy(shipped("paper1d"),
                 [](auto q, auto p) { return std::pow(1 + p[0] * p[0] / 2, 2) * (1 + q[0] * q[0]); });
  }
  SUBCASE("radial: (1 + p^2/2)^2 [1 + q^2/3 + (2/3) q^2 (p_hat . q_hat)^2]") {
    for (int dimension : {1, 2, 3, 7}) {
      CAPTURE(dimension);
      check_energy(shipped("radial", {{"dimension", dimension}}), [](auto q, auto p) {
        const double p2 = squared_norm(p), q2 = squared_norm(q);
        double dot = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) dot += p[i] * q[i];
        const double cosine2 = dot * dot / (p2 * q2);
        return std::pow(1 + p2 / 2, 2) * (1 + q2 / 3 + 2.0 / 3.0 * q2 * cosine2);
      });
    }
  }
  SUBCASE("quadratic_kinetic: p_i V_ij p_j of Henon-Heiles") {
    const double lambda = 0.8;
    check_energy(shipped("quadratic_kinetic", {{"lambda", lambda}}), [&](auto q, auto p) {
      return p[0] * p[0] + p[1] * p[1] +
             2 * lambda * (q[1] * p[0] * p[0] + 2 * q[0] * p[0] * p[1] - q[1] * p[1] * p[1]);
    });
  }
  SUBCASE("paper2d: grad T . Hess V grad T, and its lower bound 2 + |p|^2 + 2c|q|^2") {
    for (double coupling : {-0.1, 0.2, 0.3}) {
      CAPTURE(coupling);
      const auto closed_form = [&](auto q, auto p) {
        const double g0 = 1 + p[0] * p[0] / 2, g1 = 1 + p[1] * p[1] / 2, radial = 1 + squared_norm(q) / 3;
        const double h00 = radial + 2.0 / 3 * q[0] * q[0] + 2 * coupling * q[1] * q[1];
        const double h11 = radial + 2.0 / 3 * q[1] * q[1] + 2 * coupling * q[0] * q[0];
        const double h01 = (2.0 / 3 + 4 * coupling) * q[0] * q[1];
        return g0 * g0 * h00 + 2 * g0 * g1 * h01 + g1 * g1 * h11;
      };
      check_energy(shipped("paper2d", {{"coupling", coupling}}), closed_form);
      // The bound of paper2d.hpp that makes the shells compact, at random points of a wide box.
      const double c = 1.0 / 3 - std::max(coupling, -3 * coupling);
      const auto q = random_points(2000, 2, 6.0, 17), p = random_points(2000, 2, 6.0, 19);
      for (std::size_t b = 0; b < 2000; ++b) {
        const std::span<const double> qb(q.data() + 2 * b, 2), pb(p.data() + 2 * b, 2);
        CHECK(closed_form(qb, pb) >= 2 + squared_norm(pb) + 2 * c * squared_norm(qb));
      }
    }
  }
  SUBCASE("tao_product: (q^2 + 1)(p^2 + 1)/2") {
    check_energy(shipped("tao_product"), [](auto q, auto p) { return (q[0] * q[0] + 1) * (p[0] * p[0] + 1) / 2; });
  }
}

namespace {

// y = A x for the row-major n x n matrix A at a (one state).
std::vector<double> times(const std::vector<double>& a, const std::vector<double>& x) {
  const std::size_t n = x.size();
  std::vector<double> y(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) y[i] += a[i * n + j] * x[j];
  return y;
}

// The gradient of the solved H as plugin_abi.h gives it from the plugin's functions, against 5-point differences
// of the core's EnergyEvaluator. TTV: dH/dp = 2 T'' V'' T', dH/dq = d3V(q, T'(p)); VVT with T and V swapped.
void check_energy_gradient(const PluginModel& model, nonsep::HamiltonianForm form, const std::vector<double>& q,
                           const std::vector<double>& p) {
  const std::size_t n = q.size();
  const bool ttv = form == nonsep::HamiltonianForm::TTV;
  std::vector<double> grad_T(n), grad_V(n), hessian_T(n * n), hessian_V(n * n), third(n);
  model.grad_T(p, grad_T, 1);
  model.grad_V(q, grad_V, 1);
  model.hessian_T(p, hessian_T, 1);
  model.hessian_V(q, hessian_V, 1);
  // The variable of the third derivative (q for TTV, p for VVT) and the other one (p, q), from the plugin.
  std::vector<double> d_third(n),
      d_other = times(ttv ? hessian_T : hessian_V, times(ttv ? hessian_V : hessian_T, ttv ? grad_T : grad_V));
  for (double& x : d_other) x *= 2.0;
  if (ttv)
    model.d3V(q, grad_T, d_third, 1);
  else
    model.d3T(p, grad_V, d_third, 1);
  nonsep::EnergyEvaluator energy(form);
  auto h = [&](const std::vector<double>& at_q, const std::vector<double>& at_p) {
    auto x = nonsep::PhaseSpaceBatch::single(at_q, at_p);
    return energy.evaluate_one(model, x);
  };
  const double step = 1e-3;
  for (std::size_t k = 0; k < n; ++k)
    for (const bool in_q : {true, false}) {
      auto difference = [&](double offset) {
        auto shifted_q = q, shifted_p = p;
        (in_q ? shifted_q : shifted_p)[k] += offset * step;
        return h(shifted_q, shifted_p);
      };
      const double expected = (difference(-2) - 8 * difference(-1) + 8 * difference(1) - difference(2)) / (12 * step);
      const double computed = in_q == ttv ? d_third[k] : d_other[k];
      CAPTURE(k);
      CAPTURE(in_q);
      CHECK(computed == doctest::Approx(expected).epsilon(1e-8).scale(1.0));
    }
}

}  // namespace

TEST_CASE("the gradient of the solved H from the Hessians and third derivatives, as plugin_abi.h states it") {
  const std::vector<double> q3 = {0.4, -0.7, 0.25}, p3 = {-0.3, 0.9, 0.6};
  for (const auto form : {nonsep::HamiltonianForm::TTV, nonsep::HamiltonianForm::VVT}) {
    CAPTURE(form == nonsep::HamiltonianForm::TTV);
    check_energy_gradient(shipped("paper1d"), form, {0.7}, {-0.4});
    check_energy_gradient(shipped("tao_product"), form, {0.7}, {-0.4});
    check_energy_gradient(shipped("radial", {{"dimension", 3}}), form, q3, p3);
    check_energy_gradient(shipped("quadratic_kinetic", {{"lambda", 0.8}}), form, {q3[0], q3[1]}, {p3[0], p3[1]});
  }
}

TEST_CASE("radial: p = 0 is refused with an explanation, q = 0 is an ordinary point") {
  const PluginModel model = shipped("radial", {{"dimension", 3}});
  const std::vector<double> zero(3, 0.0);
  std::vector<double> gradient(3), hessian(9), value(1);
  for (const auto& call : {std::function<void()>([&] { model.grad_T(zero, gradient, 1); }),
                           std::function<void()>([&] { model.hessian_T(zero, hessian, 1); })}) {
    std::string message;
    try {
      call();
    } catch (const nonsep::ModelError& e) {
      message = e.what();
    }
    CHECK(message.find("(evaluation failed)") != std::string::npos);
    CHECK(message.find("is undefined at p = 0") != std::string::npos);
  }
  model.value_T(zero, value, 1);
  CHECK(value[0] == 0.0);
  model.grad_V(zero, gradient, 1);
  CHECK(gradient == std::vector<double>(3, 0.0));
  model.hessian_V(zero, hessian, 1);
  CHECK(hessian == std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1});
  // Arbitrarily close to p = 0 the gradient is defined, of length -> 1 along p.
  const std::vector<double> tiny = {1e-300, 0.0, 0.0};
  model.grad_T(tiny, gradient, 1);
  CHECK(gradient[0] == doctest::Approx(1.0).epsilon(1e-15));
  CHECK(gradient[1] == 0.0);
  CHECK(gradient[2] == 0.0);
}

TEST_CASE("a plugin steps bit for bit like the same model compiled in") {
  const PluginModel plugin = shipped("paper1d");
  const ModelAdapter<Paper1D> compiled_in;
  const double q0[] = {0.5}, p0[] = {0.0};
  auto through_plugin = nonsep::PhaseSpaceBatch::single(q0, p0);
  auto in_process = through_plugin;
  nonsep::ChinBasicStep a, b;
  for (int k = 0; k < 1000; ++k) {
    a.step(plugin, through_plugin, 0.005);
    b.step(compiled_in, in_process, 0.005);
  }
  CHECK(through_plugin == in_process);
  CHECK(through_plugin.q()[0] != q0[0]);
}

namespace {
// V = log(q): not finite for q <= 0 (no shipped model has such a domain).
struct LogPotential {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    using std::log;
    return log(q[0]);
  }
};
}  // namespace

TEST_CASE("a shipped model returns overflowing and NaN results as numbers, not as evaluation failures") {
  // The host, not the plugin, decides what a non-finite number means: the trajectory is reported as diverged
  // (where, when and which variable), not as failed.
  const PluginModel model = shipped("paper1d", nlohmann::json::object());
  const double huge[] = {1e120}, larger[] = {1e200}, not_a_number[] = {std::nan("")};
  double out[1] = {0.0};
  model.grad_V(huge, out, 1);  // q + q^3 / 3 overflows
  CHECK(out[0] == std::numeric_limits<double>::infinity());
  model.grad_T(larger, out, 1);  // 1 + p^2 / 2 overflows
  CHECK(out[0] == std::numeric_limits<double>::infinity());
  model.hessian_V(not_a_number, out, 1);
  CHECK(std::isnan(out[0]));
  // Automatic differentiation where the function itself is not finite gives NaN derivatives, not a finite
  // "derivative" that would let the state go on.
  const ModelAdapter<LogPotential> log_model;
  const double negative[] = {-1.0};
  log_model.grad_V(negative, out, 1);
  CHECK(std::isnan(out[0]));
}

TEST_CASE("every shipped plugin has hvp_H, the derivative of grad H along a tangent, in both forms (K + U included)") {
  const std::pair<const char*, nlohmann::json> plugins[] = {{"paper1d", nlohmann::json::object()},
                                                            {"radial", {{"dimension", 3}}},
                                                            {"quadratic_kinetic", {{"lambda", 0.8}}},
                                                            {"tao_product", nlohmann::json::object()},
                                                            {"paper2d", {{"coupling", 0.2}}},
                                                            {"mathews_lakshmanan", nlohmann::json::object()},
                                                            {"variable_mass2d", nlohmann::json::object()},
                                                            {"lattice_chain", {{"sites", 5}}}};
  for (const auto& [name, parameters] : plugins) {
    const std::string plugin_name(name);
    CAPTURE(plugin_name);
    const PluginModel model = shipped(name, parameters);
    REQUIRE(model.plugin().has_hamiltonian_hessian_products());
    CHECK(model.plugin().abi_version() == NONSEP_PLUGIN_ABI_VERSION);
    const std::size_t n = model.dimension();
    std::vector<double> q(n), p(n), dq(n), dp(n);
    for (std::size_t i = 0; i < n; ++i) {
      q[i] = 0.3 + 0.1 * static_cast<double>(i);
      p[i] = 0.5 - 0.2 * static_cast<double>(i);
      dq[i] = 1.0 - 0.3 * static_cast<double>(i);
      dp[i] = 0.4 + 0.25 * static_cast<double>(i);
    }
    for (const auto form : {nonsep::HamiltonianForm::TTV, nonsep::HamiltonianForm::VVT}) {
      CAPTURE(form == nonsep::HamiltonianForm::TTV);
      std::vector<double> out_q(n), out_p(n);
      model.hvp_H(form, q, p, dq, dp, out_q, out_p, 1);
      // Central differences of the core's grad H (hamiltonian_gradient.hpp) along (dq, dp).
      const double h = 1e-5;
      std::vector<double> gradients[2][2];
      for (int side = 0; side < 2; ++side) {
        std::vector<double> at_q = q, at_p = p;
        for (std::size_t i = 0; i < n; ++i) {
          at_q[i] += (side == 0 ? h : -h) * dq[i];
          at_p[i] += (side == 0 ? h : -h) * dp[i];
        }
        gradients[side][0].resize(n);
        gradients[side][1].resize(n);
        nonsep::HamiltonianGradient(form).evaluate(model, at_q, at_p, gradients[side][0], gradients[side][1], 1);
      }
      for (std::size_t i = 0; i < n; ++i) {
        CAPTURE(i);
        CHECK(out_q[i] == doctest::Approx((gradients[0][0][i] - gradients[1][0][i]) / (2 * h)).epsilon(1e-7));
        CHECK(out_p[i] == doctest::Approx((gradients[0][1][i] - gradients[1][1][i]) / (2 * h)).epsilon(1e-7));
      }
    }
  }
}

}  // namespace test_shipped_models
