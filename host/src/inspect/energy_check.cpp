// The energy part of `nonsep inspect --check` (plugin_report.hpp, check_product_energy): a plugin's own product term
// of H (energy_TTV, energy_VVT) against the core's rule, H from its Hessian-vector products or its Hessians.
#include <algorithm>
#include <string>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
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
    PathDifference difference;
    for (std::size_t b = 0; b < count; ++b) difference.add(rule[b], own[b]);
    result.text += line + result.judge(difference, tolerance, "the rule", "relative to max(1, |H|)") + "\n";
  }
  return result;
}

}  // namespace nonsep::host
