#include "nonsep/host/plugin_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <span>

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
    if (parameter.minimum || parameter.maximum)
      range = "[" + (parameter.minimum ? format_number(*parameter.minimum) : std::string("-inf")) + ", " +
              (parameter.maximum ? format_number(*parameter.maximum) : std::string("inf")) + "]";
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

using Evaluate = std::function<void(std::span<const double>, std::span<double>, std::size_t)>;

struct Checker {
  DerivativeCheck& result;
  double tolerance;

  void line(const std::string& what) { result.lines.push_back({what, 0.0, true, ""}); }
  void compare(DerivativeCheckLine& line, double analytic, double numeric, const std::string& where) {
    const double error = std::abs(analytic - numeric) / std::max(1.0, std::abs(analytic));
    line.worst_error = std::isnan(error) ? INFINITY : std::max(line.worst_error, error);
    if (!(error <= tolerance) && line.passed) {
      line.passed = false;
      result.passed = false;
      line.note = "at " + where + ": analytic " + format_number(analytic) + ", finite difference " +
                  format_number(numeric);
    }
  }
};

std::string point_text(const char* variable, std::span<const double> x) {
  std::string text = std::string(variable) + " = (";
  for (std::size_t i = 0; i < x.size(); ++i) text += (i ? ", " : "") + format_number(x[i]);
  return text + ")";
}

// Derivative of `function` (outputs `width` numbers per point) along component i, by a central difference
// with step h = cbrt(machine epsilon) * max(1, |x_i|).
std::vector<double> central_difference(const Evaluate& function, std::span<const double> x, std::size_t i,
                                       std::size_t width) {
  std::vector<double> plus(x.begin(), x.end()), minus(x.begin(), x.end());
  const double h = 6.0554544523933395e-06 * std::max(1.0, std::abs(x[i]));
  plus[i] += h;
  minus[i] -= h;
  std::vector<double> f_plus(width), f_minus(width), derivative(width);
  function(plus, f_plus, 1);
  function(minus, f_minus, 1);
  for (std::size_t k = 0; k < width; ++k) derivative[k] = (f_plus[k] - f_minus[k]) / (plus[i] - minus[i]);
  return derivative;
}

}  // namespace

DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin, std::size_t points, double tolerance) {
  DerivativeCheck result;
  Checker check{result, tolerance};
  const std::size_t n = model.dimension();
  // Fixed points in [-1, 1]^n from a 64-bit linear congruential generator: the same on every machine.
  std::vector<double> at(points * n);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  for (double& x : at) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    x = 2.0 * static_cast<double>(state >> 11) / 9007199254740992.0 - 1.0;
  }
  for (const char* which : {"T", "V"}) {
    const bool kinetic = which[0] == 'T';
    const char* variable = kinetic ? "p" : "q";
    const std::string suffix = kinetic ? "_T" : "_V";
    const Evaluate value = [&](std::span<const double> x, std::span<double> out, std::size_t count) {
      kinetic ? model.value_T(x, out, count) : model.value_V(x, out, count);
    };
    const Evaluate gradient = [&](std::span<const double> x, std::span<double> out, std::size_t count) {
      kinetic ? model.grad_T(x, out, count) : model.grad_V(x, out, count);
    };
    const Evaluate hessian = [&](std::span<const double> x, std::span<double> out, std::size_t count) {
      kinetic ? model.hessian_T(x, out, count) : model.hessian_V(x, out, count);
    };
    std::vector<double> g(points * n), h(points * n * n);
    gradient(at, g, points);
    if (plugin.has_hessians()) hessian(at, h, points);

    // Four lines per function; references are taken after all four exist (push_back may reallocate).
    const std::size_t first = result.lines.size();
    check.line("grad" + suffix + " vs value" + suffix);
    check.line("hessian" + suffix + " vs grad" + suffix);
    check.line("hessian" + suffix + " symmetry");
    check.line("grad" + suffix + " batch consistency");
    auto& grad_line = result.lines[first];
    auto& hessian_line = result.lines[first + 1];
    auto& symmetry_line = result.lines[first + 2];
    auto& batch_line = result.lines[first + 3];
    if (!plugin.has_values()) grad_line.note = "skipped: the plugin has no value_T / value_V";
    if (!plugin.has_hessians()) hessian_line.note = symmetry_line.note = "skipped: the plugin has no Hessians";
    for (std::size_t b = 0; b < points; ++b) {
      const auto x = std::span<const double>(at).subspan(b * n, n);
      const std::string where = point_text(variable, x);
      for (std::size_t i = 0; i < n; ++i) {
        if (plugin.has_values())
          check.compare(grad_line, g[b * n + i], central_difference(value, x, i, 1)[0], where);
        if (plugin.has_hessians()) {
          const auto column = central_difference(gradient, x, i, n);
          for (std::size_t k = 0; k < n; ++k) {
            check.compare(hessian_line, h[b * n * n + k * n + i], column[k], where);
            check.compare(symmetry_line, h[b * n * n + k * n + i], h[b * n * n + i * n + k], where);
          }
        }
      }
      std::vector<double> alone(n);
      gradient(x, alone, 1);
      for (std::size_t i = 0; i < n; ++i)
        if (alone[i] != g[b * n + i] && batch_line.passed) {
          batch_line.passed = result.passed = false;
          batch_line.worst_error = INFINITY;
          batch_line.note = "at " + where + ": component " + std::to_string(i) + " is " + format_number(alone[i]) +
                            " alone but " + format_number(g[b * n + i]) + " in a batch";
        }
    }
  }
  return result;
}

std::string format_derivative_check(const DerivativeCheck& check) {
  std::string out;
  for (const auto& line : check.lines) {
    const bool skipped = line.note.rfind("skipped", 0) == 0;
    char error[32];
    std::snprintf(error, sizeof error, "%.2e", line.worst_error);
    out += "  " + pad(skipped ? "skip" : line.passed ? "ok" : "FAIL", 5) + pad(line.what, 34) +
           (skipped ? std::string() : "worst scaled error " + std::string(error)) +
           (line.note.empty() ? "" : (skipped ? "" : "  ") + line.note) + "\n";
  }
  out += check.passed ? "derivative check passed\n" : "derivative check FAILED\n";
  return out;
}

}  // namespace nonsep::host
