// What `nonsep inspect` and `nonsep models` print about a plugin (plugin_report.hpp).
#include "nonsep/host/inspect/plugin_report.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "nonsep/host/number_format.hpp"
#include "nonsep/plugin_abi.h"

namespace nonsep::host {

using nlohmann::json;

namespace {

std::string text_of(const json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) return format_number(value.get<double>());
  return value.dump();
}

std::string dimension_text(const json& metadata) {
  const json dimension = metadata.value("dimension", json::object());
  if (dimension.contains("fixed")) return text_of(dimension["fixed"]);
  if (dimension.contains("parameter")) return "parameter " + text_of(dimension["parameter"]);
  return "?";
}

std::string pad(std::string text, std::size_t width) {
  if (text.size() < width) text.append(width - text.size(), ' ');
  return text;
}

}  // namespace

std::string describe_plugin(const Plugin& plugin) {
  const json& metadata = plugin.metadata();
  std::string out;
  out += plugin.name() + " " + plugin.version() + "\n";
  out += "  file:        " + plugin.path().string() + "\n";
  out += "  description: " + plugin.description() + "\n";
  if (metadata.contains("hamiltonian")) out += "  hamiltonian: " + text_of(metadata["hamiltonian"]) + "\n";
  out += "  dimension:   " + dimension_text(metadata) + "\n";
  out += "  plugin ABI:  version " + std::to_string(plugin.abi_version()) +
         (plugin.abi_version() < NONSEP_PLUGIN_ABI_VERSION ? " (still loaded; rebuild it for the entries of version " +
                                                                 std::to_string(NONSEP_PLUGIN_ABI_VERSION) + ")"
                                                           : "") +
         "\n";
  std::string capabilities;
  const json capabilities_object = metadata.value("capabilities", json::object());
  for (const auto& [name, present] : capabilities_object.items())
    capabilities += (capabilities.empty() ? "" : ", ") + name + (present == true ? "" : " (absent)");
  const bool general = plugin.general_hamiltonian();
  out +=
      std::string("  form:        ") +
      (general ? "given by H(q, p) itself (plugin ABI version 6): the schemes gauss, implicit_midpoint and tao; Chin's "
                 "schemes need the product form"
               : "product form T_i V_ij T_j (+ K + U): every scheme") +
      "\n";
  out += std::string("  functions:   ") + (general ? "" : "grad_T, grad_V") +
         (capabilities.empty() ? "" : (general ? "" : ", ") + capabilities) + "\n";
  if (metadata.contains("derivatives") && metadata["derivatives"].is_object()) {
    std::string derivatives;
    for (const auto& [name, how] : metadata["derivatives"].items())
      derivatives += (derivatives.empty() ? "" : ", ") + name + " " + text_of(how);
    out += "  derivatives: " + derivatives + "\n";
  }
  out += "  threads:     " +
         std::string(plugin.thread_safe() ? "thread-safe (one instance per thread)"
                                          : "not thread-safe (\"thread_safe\": false: one instance on one thread)") +
         "\n";
  const KernelChoice& kernels = plugin.kernels();
  std::string sets;
  for (const auto& name : kernels.instruction_sets) sets += (sets.empty() ? "" : ", ") + name;
  out += "  kernels:     " +
         (kernels.present ? "version " + std::to_string(kernels.version) + " for " + sets + "; runs use " +
                                (kernels.chosen ? kernels.chosen_name() + " (" + kernels.note + ")" : kernels.note)
                          : std::string("none (the evaluation path)")) +
         "\n";
  std::string written;  // the forms whose product term the plugin writes out
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT})
    if (plugin.has_product_energy(form))
      written += std::string(written.empty() ? "" : " and ") + (form == HamiltonianForm::TTV ? "H_TTV" : "H_VVT");
  out += "  energy:      " +
         std::string(general ? "available (value_H)"
                     : plugin.has_hessians()
                         ? "available (the plugin has both Hessians" +
                               (written.empty() ? std::string() : "; writes out " + written + ", one pass") + ")"
                         : "not available: the plugin lacks hessian_T or hessian_V") +
         "\n";
  const auto parameters = plugin.parameters();
  if (parameters.empty()) {
    out += "  parameters:  none\n";
    return out;
  }
  std::vector<std::vector<std::string>> rows{{"name", "type", "default", "range", "unit", "description"}};
  for (const auto& parameter : parameters) {
    std::string range;
    if (parameter.minimum || parameter.maximum) {
      range += '[';
      range += parameter.minimum ? format_number(*parameter.minimum) : "-inf";
      range += ", ";
      range += parameter.maximum ? format_number(*parameter.maximum) : "inf";
      range += ']';
    }
    rows.push_back({parameter.name, parameter.type, text_of(parameter.default_value), range.empty() ? "-" : range,
                    parameter.unit.empty() ? "-" : parameter.unit, parameter.description});
  }
  std::vector<std::size_t> widths(rows[0].size(), 0);
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  out += "  parameters:\n";
  for (const auto& row : rows) {
    std::string line = "   ";
    for (std::size_t c = 0; c < row.size(); ++c) line += " " + (c + 1 == row.size() ? row[c] : pad(row[c], widths[c]));
    out += line + "\n";
  }
  return out;
}

std::string describe_discovered(const DiscoveredPlugin& discovered) {
  if (!discovered.plugin) return "(failed)  " + discovered.path.string() + "  " + discovered.error;
  const Plugin& plugin = *discovered.plugin;
  return plugin.name() + "  " + plugin.version() + "  dimension " + dimension_text(plugin.metadata()) + "  " +
         discovered.path.string() + "  " + plugin.description();
}

}  // namespace nonsep::host
