// The shipped models with a separable part, loaded as plugins: mathews_lakshmanan (U only) and variable_mass2d (K
// and U). They announce K and U as capabilities (ABI version 4 on), pass the derivative checker on T, V, K and U,
// their energy is the full H = T_i V_ij T_j + K + U they document, the comparators' grad H is its gradient, and a
// plugin steps bit for bit like the same model compiled in, through every Chin scheme.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mathews_lakshmanan/mathews_lakshmanan.hpp"
#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"
#include "nonsep/reference/mathews_lakshmanan_exact.hpp"
#include "support/models.hpp"
#include "variable_mass2d/variable_mass2d.hpp"

namespace test_shipped_separable {

using nonsep::host::load_plugin;
using nonsep::host::PluginModel;

namespace {

PluginModel shipped(const std::string& name, const nlohmann::json& parameters = nlohmann::json::object()) {
  return load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/" + name + ".so", "").create(parameters);
}

static_assert(nonsep::ModelWithSeparablePart<PluginModel>);

}  // namespace

TEST_CASE("shipped separable models: capabilities, derivatives and documentation") {
  const PluginModel oscillator = shipped("mathews_lakshmanan"), plane = shipped("variable_mass2d");
  CHECK(oscillator.plugin().abi_version() == NONSEP_PLUGIN_ABI_VERSION);
  CHECK_FALSE(oscillator.has_K());
  CHECK(oscillator.has_U());
  CHECK(plane.has_K());
  CHECK(plane.has_U());
  const auto& capabilities = oscillator.plugin().metadata()["capabilities"];
  CHECK(capabilities["grad_U"] == true);
  CHECK(capabilities["value_U"] == true);
  CHECK(capabilities["hessian_U"] == true);
  CHECK(capabilities["grad_K"] == false);
  CHECK(oscillator.plugin().metadata()["derivatives"]["grad_U"] == "analytic");
  CHECK(plane.plugin().metadata()["derivatives"]["grad_K"] == "automatic");
  for (const PluginModel* model : {&oscillator, &plane}) {
    CAPTURE(model->plugin().name());
    CHECK(model->plugin().has_hessians());
    CHECK(model->plugin().has_third_derivatives());
    for (const auto& report : {nonsep::check_derivatives(*model), nonsep::check_separable_derivatives(*model)}) {
      INFO(report.summary());
      CHECK(report.passed());
      CHECK(report.comparisons > 0);
    }
    const std::string hamiltonian = model->plugin().metadata()["hamiltonian"].get<std::string>();
    CHECK(hamiltonian.find("U = ") != std::string::npos);
  }
  // The absent K of the oscillator is refused by name, not evaluated as something.
  std::vector<double> x(1), out(1);
  CHECK_THROWS_WITH_AS(oscillator.grad_K(x, out, 1), doctest::Contains("does not provide grad_K"), nonsep::ModelError);
}

TEST_CASE("shipped separable models: the energy is the full H, and grad H its gradient") {
  const nonsep::reference::MathewsLakshmanan exact{0.8, 1.3};
  const PluginModel oscillator = shipped("mathews_lakshmanan", {{"lambda", 0.8}, {"alpha", 1.3}});
  const nonsep::testing::VariableMass2D twin;
  const PluginModel plane = shipped("variable_mass2d");
  nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
  for (const double q : {-1.7, 0.0, 0.4, 2.5})
    for (const double p : {-0.9, 0.3}) {
      const double qs[] = {q}, ps[] = {p};
      CHECK(energy.evaluate_one(oscillator, nonsep::PhaseSpaceBatch::single(qs, ps)) ==
            doctest::Approx(exact.hamiltonian(q, p)).epsilon(1e-14));
    }
  const double z[4] = {0.4, -0.9, 0.7, -0.3};
  const auto x = nonsep::PhaseSpaceBatch::single(std::vector<double>{z[0], z[1]}, std::vector<double>{z[2], z[3]});
  CHECK(energy.evaluate_one(plane, x) == doctest::Approx(twin.hamiltonian(z)).epsilon(1e-14));
  nonsep::HamiltonianGradient gradient(nonsep::HamiltonianForm::TTV);
  std::vector<double> dq(2), dp(2), dq_twin(2), dp_twin(2);
  gradient.evaluate(plane, x.q(), x.p(), dq, dp, 1);
  gradient.evaluate(twin, x.q(), x.p(), dq_twin, dp_twin, 1);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(dq[i] == doctest::Approx(dq_twin[i]).epsilon(1e-14));
    CHECK(dp[i] == doctest::Approx(dp_twin[i]).epsilon(1e-14));
  }
}

TEST_CASE("shipped separable models: a plugin steps bit for bit like the same model compiled in") {
  const PluginModel plugin = shipped("variable_mass2d");
  const nonsep::sdk::ModelAdapter<VariableMass2D> compiled_in;
  const nonsep::IntegratorSpec specs[] = {{"basic", nonsep::ChinOptions{nonsep::Fraction(2, 3)}},
                                          {"triplet", nonsep::ChinOptions{nonsep::Fraction(2)}},
                                          {"mpe", nonsep::ChinOptions{nonsep::Fraction(4, 3)}}};
  for (const auto& spec : specs) {
    CAPTURE(spec.scheme);
    auto through_plugin =
        nonsep::PhaseSpaceBatch::single(std::vector<double>{0.5, -0.2}, std::vector<double>{0.1, 0.3});
    auto in_process = through_plugin;
    nonsep::Integrator a(spec), b(spec);
    for (int k = 0; k < 50; ++k) {
      a.step(plugin, through_plugin, 0.01);
      b.step(compiled_in, in_process, 0.01);
    }
    CHECK(through_plugin == in_process);
    CHECK(a.evaluations() == b.evaluations());
    CHECK(a.evaluations().grad_K > 0);
  }
}

}  // namespace test_shipped_separable
