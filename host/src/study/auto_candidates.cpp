// Scheme "auto": what a model offers it and the candidates it tries (scheme_choice.hpp).
#include <algorithm>
#include <utility>
#include <vector>

#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/study/scheme_choice.hpp"

namespace nonsep::host {

AutoModel auto_model(const Plugin& plugin) {
  return {plugin.general_hamiltonian(), plugin.has_hessians() && plugin.has_third_derivatives(),
          plugin.has_hamiltonian_hessian_products()};
}

AutoModel auto_model(const formula::FormulaModel& model) {
  // Its plugin's functions are templates of the number type: the SDK differentiates them to every order.
  return {model.h_tree.has_value(), true, true};
}

std::vector<AutoCandidate> auto_candidates(const LoadedJob& loaded) {
  return auto_candidates(loaded.job, auto_model(loaded.plugin));
}

std::vector<AutoCandidate> auto_candidates(const Job& job, const AutoModel& model) {
  const SingleRun& run = job.run();
  const HamiltonianForm form = run.integrator.form;
  // The catalogue's auto_orders, fastest first so that the pilots of slower ones are cut short: the comparators'
  // before Chin's, each by falling order.
  std::vector<std::pair<const Scheme*, Fraction>> orders;
  for (const Scheme& scheme : scheme_catalogue())
    for (const Fraction& order : scheme.auto_orders) orders.emplace_back(&scheme, order);
  std::stable_sort(orders.begin(), orders.end(), [](const auto& a, const auto& b) {
    const bool a_first = a.first->family == "comparator", b_first = b.first->family == "comparator";
    return a_first != b_first ? a_first : b.second.value() < a.second.value();
  });
  // A model given by H (general_hamiltonian) has the gradient of H and no product form for Chin's schemes; a
  // comparator's tangent map needs the plugin's directional derivative of grad H (hvp_H) besides.
  const bool general = model.general;
  const bool gradient_of_h = general || model.hessians_and_third_derivatives;
  std::vector<AutoCandidate> usable;
  for (const auto& [scheme, order] : orders) {
    const bool comparator = scheme->family == "comparator";
    if (comparator ? !gradient_of_h : general) continue;
    IntegratorSpec spec = spec_of_order(*scheme, order, form);
    if (run.analysis.tangent_vectors() > 0 && (!has_tangent_map(spec) || (comparator && !model.hessian_products)))
      continue;
    usable.push_back({scheme->name + " " + order.to_string(), std::move(spec)});
  }
  return usable;
}

}  // namespace nonsep::host
