// Loads the plugin that examples/external_model built against an installed nonsep, through the loader library,
// and checks that it is the model the example describes: metadata, parameters, derivatives (checker), and that
// the basic step conserves its H_TTV. Usage: nonsep_external_model_check <plugin.so>. Exit status 0 when all hold.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace {
int failures = 0;
void expect(bool holds, const std::string& what) {
  std::printf("%s: %s\n", holds ? "ok" : "FAILED", what.c_str());
  failures += !holds;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <plugin.so>\n", argv[0]);
    return 2;
  }
  try {
    const auto plugin = nonsep::host::load_plugin(argv[1], std::filesystem::current_path());
    expect(plugin.name() == "relativistic_pendulum", "metadata name is relativistic_pendulum");
    const auto parameters = plugin.parameters();
    expect(parameters.size() == 1 && parameters[0].name == "g" && parameters[0].unit == "1/time^2",
           "parameter g with its unit");
    expect(plugin.has_values() && plugin.has_hessians() && plugin.has_third_derivatives(),
           "values, Hessians and third derivatives (filled in by the SDK)");
    expect(plugin.thread_safe(), "thread_safe, as the SDK declares");
    const auto model = plugin.create({{"g", 2.0}});
    const auto report = nonsep::check_derivatives(model);
    expect(report.passed() && report.comparisons > 0 && report.skipped.empty(),
           "derivative check: " + report.summary());

    // H_TTV = g cos(q) p^2 / (1 + p^2) is conserved to O(dt^(2/3)) over a stretch of the orbit.
    const double q0[] = {0.3}, p0[] = {1.0};
    auto x = nonsep::PhaseSpaceBatch::single(q0, p0);
    nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
    const double h0 = energy.evaluate_one(model, x);
    expect(std::abs(h0 - 2.0 * std::cos(0.3) * 0.5) < 1e-14, "energy of the initial state");
    nonsep::ChinBasicStep step;
    double worst = 0.0;
    for (int k = 0; k < 2000; ++k) {
      step.step(model, x, 1e-4);
      const double drift = std::abs(energy.evaluate_one(model, x) - h0);
      worst = std::isnan(worst) || std::isnan(drift) ? std::nan("") : std::max(worst, drift);  // NaN is kept
    }
    expect(worst < 1e-3 && x.q()[0] != q0[0],
           "H_TTV conserved while the state moves (largest drift " + std::to_string(worst) + ")");
  } catch (const std::exception& e) {
    expect(false, std::string("exception: ") + e.what());
  }
  return failures == 0 ? 0 : 1;
}
