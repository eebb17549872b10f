// The energy part of `nonsep inspect --check` (plugin_report.hpp, check_product_energy): a plugin's own product term
// of H (energy_TTV, energy_VVT) against the core's rule, H from its Hessian-vector products or its Hessians.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "nonsep/core/energy.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"

namespace nonsep::host {

PathCheck check_product_energy(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                               std::span<const double> p, std::size_t count, double tolerance) {
  PathCheck result;
  const std::size_t n = model.dimension();
  PhaseSpaceBatch x(n, count);
  std::copy_n(q.begin(), x.size(), x.q().begin());
  std::copy_n(p.begin(), x.size(), x.p().begin());
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    const std::string name = form == HamiltonianForm::TTV ? "energy_TTV" : "energy_VVT";
    if (!plugin.has_product_energy(form)) continue;
    std::string line = name + " (written out) against the products or Hessians, " + std::to_string(count) + " states: ";
    std::vector<double> own(count), rule(count);
    try {
      EnergyEvaluator(form).evaluate(model, x, own);
      EnergyEvaluator(form).evaluate(model.without_product_energy(), x, rule);
    } catch (const ModelError& error) {
      result.text += line + "not compared (" + error.what() + ")\n";
      continue;
    }
    double largest = 0.0;
    bool comparable = true;
    for (std::size_t b = 0; b < count; ++b) {
      if (std::isfinite(own[b]) != std::isfinite(rule[b])) comparable = false;
      if (std::isfinite(own[b]) && std::isfinite(rule[b]))
        largest = std::max(largest, std::abs(own[b] - rule[b]) / std::max(1.0, std::abs(rule[b])));
    }
    if (!comparable) {
      line += "FAILED: non-finite where the rule is finite (or the reverse)";
      result.passed = false;
    } else {
      char text[64];
      std::snprintf(text, sizeof text, "%.3g", largest);
      line += std::string("largest difference ") + text + " (relative to max(1, |H|))";
      if (largest > tolerance) {
        line += ": FAILED, above the tolerance";
        result.passed = false;
      }
    }
    result.largest_difference = std::max(result.largest_difference, largest);
    result.text += line + "\n";
  }
  return result;
}

}  // namespace nonsep::host
