#include "nonsep/host/plugin_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>

#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/number_format.hpp"

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
  std::string capabilities;
  const json capabilities_object = metadata.value("capabilities", json::object());
  for (const auto& [name, present] : capabilities_object.items())
    capabilities += (capabilities.empty() ? "" : ", ") + name + (present == true ? "" : " (absent)");
  out += "  functions:   grad_T, grad_V" + (capabilities.empty() ? "" : ", " + capabilities) + "\n";
  if (metadata.contains("derivatives") && metadata["derivatives"].is_object()) {
    std::string derivatives;
    for (const auto& [name, how] : metadata["derivatives"].items())
      derivatives += (derivatives.empty() ? "" : ", ") + name + " " + text_of(how);
    out += "  derivatives: " + derivatives + "\n";
  }
  out += "  energy:      " +
         std::string(plugin.has_hessians() ? "available (the plugin has both Hessians)"
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

namespace {

std::string point_text(const char* variable, std::span<const double> x) {
  std::string text = std::string(variable) + " = (";
  for (std::size_t i = 0; i < x.size(); ++i) text += (i ? ", " : "") + format_number(x[i]);
  return text + ")";
}

// One call on all points must give, bit for bit, what one call per point gives: the runner steps an ensemble as
// one batch and retires states from it, which is only invisible to the others if states do not interact.
// Returns "" or a description of the first difference.
std::string batch_difference(const PluginModel& model, const Plugin& plugin, std::size_t points) {
  const std::size_t n = model.dimension();
  std::vector<double> at(points * n);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;  // a 64-bit LCG: the same points on every machine
  for (double& x : at) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    x = 3.0 * static_cast<double>(state >> 11) / 9007199254740992.0 - 1.5;
  }
  struct Function {
    const char* name;
    const char* variable;
    std::size_t width;
    void (PluginModel::*evaluate)(std::span<const double>, std::span<double>, std::size_t) const;
  };
  std::vector<Function> functions{{"grad_T", "p", n, &PluginModel::grad_T}, {"grad_V", "q", n, &PluginModel::grad_V}};
  if (plugin.has_hessians()) {
    functions.push_back({"hessian_T", "p", n * n, &PluginModel::hessian_T});
    functions.push_back({"hessian_V", "q", n * n, &PluginModel::hessian_V});
  }
  for (const auto& function : functions) {
    std::vector<double> batch(points * function.width), alone(function.width);
    (model.*function.evaluate)(at, batch, points);
    for (std::size_t b = 0; b < points; ++b) {
      const auto x = std::span<const double>(at).subspan(b * n, n);
      (model.*function.evaluate)(x, alone, 1);
      for (std::size_t i = 0; i < function.width; ++i)
        if (alone[i] != batch[b * function.width + i])
          return std::string(function.name) + "[" + std::to_string(i) + "] at " + point_text(function.variable, x) +
                 " is " + format_number(alone[i]) + " alone but " + format_number(batch[b * function.width + i]) +
                 " in a batch of " + std::to_string(points);
    }
  }
  return "";
}

}  // namespace

DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin) {
  DerivativeCheckOptions options;
  options.check_gradients = plugin.has_values();
  options.check_hessians = plugin.has_hessians();
  const DerivativeCheckReport report = nonsep::check_derivatives(model, options);
  DerivativeCheck result;
  result.text = report.summary();
  if (!options.check_gradients) result.text += "  skipped: gradients: the plugin has no value_T/value_V\n";
  if (!options.check_hessians) result.text += "  skipped: Hessians: the plugin has no hessian_T/hessian_V\n";
  const std::string difference = batch_difference(model, plugin, options.random_points);
  result.text += difference.empty() ? "batch consistency: one call on all points equals one call per point\n"
                                    : "batch consistency FAILED: " + difference + "\n";
  result.passed = report.passed() && difference.empty();
  result.text += result.passed ? "derivative check passed\n" : "derivative check FAILED\n";
  return result;
}

}  // namespace nonsep::host
