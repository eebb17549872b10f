#include "nonsep/host/plugin_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <thread>
#include <vector>
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
  out += "  threads:     " +
         std::string(plugin.thread_safe() ? "thread-safe (one instance per thread)"
                                          : "not thread-safe (\"thread_safe\": false: one instance on one thread)") +
         "\n";
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

// Points in [-1.5, 1.5]^n from a 64-bit LCG: the same on every machine.
std::vector<double> sample_points(std::size_t size, std::uint64_t state) {
  std::vector<double> at(size);
  for (double& x : at) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    x = 3.0 * static_cast<double>(state >> 11) / 9007199254740992.0 - 1.5;
  }
  return at;
}

// The batched functions the plugin has, as (model, x, u, out, count) calls; u is read by d3T and d3V only.
struct EvaluationFunction {
  const char* name;
  const char* variable;
  std::size_t width;  // outputs per state
  void (*evaluate)(const PluginModel&, std::span<const double>, std::span<const double>, std::span<double>,
                   std::size_t);
};

std::vector<EvaluationFunction> evaluation_functions(const Plugin& plugin, std::size_t n) {
  using X = std::span<const double>;
  using Out = std::span<double>;
  using M = const PluginModel&;
  using C = std::size_t;
  std::vector<EvaluationFunction> functions{
      {"grad_T", "p", n, [](M m, X x, X, Out out, C c) { m.grad_T(x, out, c); }},
      {"grad_V", "q", n, [](M m, X x, X, Out out, C c) { m.grad_V(x, out, c); }}};
  if (plugin.has_hessians()) {
    functions.push_back({"hessian_T", "p", n * n, [](M m, X x, X, Out out, C c) { m.hessian_T(x, out, c); }});
    functions.push_back({"hessian_V", "q", n * n, [](M m, X x, X, Out out, C c) { m.hessian_V(x, out, c); }});
  }
  if (plugin.has_third_derivatives()) {
    functions.push_back({"d3T", "p", n, [](M m, X x, X u, Out out, C c) { m.d3T(x, u, out, c); }});
    functions.push_back({"d3V", "q", n, [](M m, X x, X u, Out out, C c) { m.d3V(x, u, out, c); }});
  }
  return functions;
}

// The sample points and directions of the consistency checks.
struct Samples {
  std::size_t count;
  std::vector<double> at, directions;
  Samples(std::size_t n, std::size_t points)
      : count(points),
        at(sample_points(points * n, 0x9E3779B97F4A7C15ull)),
        directions(sample_points(points * n, 0xD1B54A32D192ED03ull)) {}
};

// One call on all points must give, bit for bit, what one call per point gives: the runner steps an ensemble as
// one batch and retires states from it, which is only invisible to the others if states do not interact.
// Returns "" or a description of the first difference.
std::string batch_difference(const PluginModel& model, const Plugin& plugin, const Samples& samples) {
  const std::size_t n = model.dimension(), points = samples.count;
  for (const auto& function : evaluation_functions(plugin, n)) {
    std::vector<double> batch(points * function.width), alone(function.width);
    function.evaluate(model, samples.at, samples.directions, batch, points);
    for (std::size_t b = 0; b < points; ++b) {
      const auto x = std::span<const double>(samples.at).subspan(b * n, n);
      function.evaluate(model, x, std::span<const double>(samples.directions).subspan(b * n, n), alone, 1);
      for (std::size_t i = 0; i < function.width; ++i)
        if (alone[i] != batch[b * function.width + i])
          return std::string(function.name) + "[" + std::to_string(i) + "] at " + point_text(function.variable, x) +
                 " is " + format_number(alone[i]) + " alone but " + format_number(batch[b * function.width + i]) +
                 " in a batch of " + std::to_string(points);
    }
  }
  return "";
}

// For a plugin that says "thread_safe": true, two instances used at the same time on two threads must give, bit
// for bit, what one instance gives on one thread: the runner gives each worker thread its own instance. Each
// thread makes `rounds` passes over every function on all points, comparing each result with the one-thread one.
// Returns "" or a description of the first difference; rethrows an evaluation failure.
std::string thread_difference(const PluginModel& model, const Plugin& plugin, const Samples& samples,
                              std::size_t rounds) {
  const std::size_t points = samples.count;
  const auto functions = evaluation_functions(plugin, model.dimension());
  std::vector<std::vector<double>> reference;
  for (const auto& function : functions) {
    reference.emplace_back(points * function.width);
    function.evaluate(model, samples.at, samples.directions, reference.back(), points);
  }
  const PluginModel second = plugin.create(model.parameters());
  std::string found[2];
  std::exception_ptr failure[2];
  auto work = [&](int thread, const PluginModel& instance) {
    try {
      for (std::size_t round = 0; round < rounds && found[thread].empty(); ++round)
        for (std::size_t f = 0; f < functions.size() && found[thread].empty(); ++f) {
          std::vector<double> out(reference[f].size());
          functions[f].evaluate(instance, samples.at, samples.directions, out, points);
          for (std::size_t k = 0; k < out.size(); ++k)
            if (std::memcmp(&out[k], &reference[f][k], sizeof(double)) != 0) {
              found[thread] = std::string(functions[f].name) + "[" + std::to_string(k) + "] of a batch of " +
                              std::to_string(points) + " is " + format_number(reference[f][k]) +
                              " on one thread but " + format_number(out[k]) + " on thread " +
                              std::to_string(thread + 1) + " of 2 (round " + std::to_string(round + 1) + ")";
              break;
            }
        }
    } catch (...) {
      failure[thread] = std::current_exception();
    }
  };
  std::thread other(work, 1, std::cref(second));
  work(0, model);
  other.join();
  for (const auto& f : failure)
    if (f) std::rethrow_exception(f);
  return found[0].empty() ? found[1] : found[0];
}

}  // namespace

DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin) {
  DerivativeCheckOptions options;
  options.check_gradients = plugin.has_values();
  options.check_hessians = plugin.has_hessians();
  options.check_third_derivatives = plugin.has_third_derivatives() && plugin.has_hessians();
  const DerivativeCheckReport report = nonsep::check_derivatives(model, options);
  DerivativeCheck result;
  result.text = report.summary();
  if (!options.check_gradients) result.text += "  skipped: gradients: the plugin has no value_T/value_V\n";
  if (!options.check_hessians) result.text += "  skipped: Hessians: the plugin has no hessian_T/hessian_V\n";
  if (!options.check_third_derivatives)
    result.text += plugin.has_third_derivatives()
                       ? "  skipped: third derivatives: differencing them needs hessian_T/hessian_V\n"
                       : "  skipped: third derivatives: the plugin has no d3T/d3V\n";
  const Samples samples(model.dimension(), options.random_points);
  const std::string difference = batch_difference(model, plugin, samples);
  result.text += difference.empty() ? "batch consistency: one call on all points equals one call per point\n"
                                    : "batch consistency FAILED: " + difference + "\n";
  std::string threads;
  if (plugin.thread_safe()) {
    threads = thread_difference(model, plugin, samples, 16);
    result.text += threads.empty() ? "threads: two instances on two threads give the numbers of one thread\n"
                                   : "threads FAILED: " + threads +
                                         " (instances share mutable state: the plugin must declare "
                                         "\"thread_safe\": false, or keep its state per instance)\n";
  } else {
    result.text += "threads: skipped: the plugin declares \"thread_safe\": false (the host runs it as one instance on "
                   "one thread)\n";
  }
  result.passed = report.passed() && difference.empty() && threads.empty();
  result.text += result.passed ? "derivative check passed\n" : "derivative check FAILED\n";
  return result;
}

}  // namespace nonsep::host
