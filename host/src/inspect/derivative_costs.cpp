// `nonsep inspect`'s derivative costs (plugin_report.hpp): each function timed on one batch, repeatedly.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <random>
#include <vector>

#include "nonsep/host/inspect/plugin_report.hpp"

namespace nonsep::host {

namespace {

using Clock = std::chrono::steady_clock;

// Nanoseconds per state of one call of `call` on `count` states: calls repeated for about 10 ms (at least once).
double nanoseconds_per_state(const std::function<void()>& call, std::size_t count) {
  call();  // first touch: pages, caches, lazily built tables
  const auto start = Clock::now();
  std::size_t calls = 0;
  do {
    call();
    ++calls;
  } while (Clock::now() - start < std::chrono::milliseconds(10));
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return seconds * 1e9 / static_cast<double>(calls * count);
}

std::string cost_text(double nanoseconds) {
  char text[32];
  std::snprintf(text, sizeof text,
                nanoseconds < 100   ? "%.1f ns"
                : nanoseconds < 1e5 ? "%.0f ns"
                                    : "%.3g ns",
                nanoseconds);
  return text;
}

}  // namespace

std::string describe_derivative_costs(const Plugin& plugin, const PluginModel& model) {
  const nlohmann::json& metadata = plugin.metadata();
  const nlohmann::json how = metadata.value("derivatives", nlohmann::json::object());
  const std::size_t n = model.dimension();
  const std::size_t count = std::clamp<std::size_t>(4096 / n, 1, 32);
  std::mt19937_64 random(2009);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> x(count * n), u(count * n), out(count * n), out2(count * n), matrix;
  for (auto* v : {&x, &u})
    for (double& value : *v) value = uniform(random);
  const bool hessians_fit = n <= 1024;
  if (hessians_fit) matrix.resize(count * n * n);

  struct Function {
    const char* name;
    bool present;
    std::function<void()> call;
  };
  const bool general = plugin.general_hamiltonian();  // H itself at (q, p) = (x, u)
  const std::vector<Function> functions = {
      {"value_H", general, [&] { model.value_H(x, u, out, count); }},
      {"grad_H", general, [&] { model.grad_H(x, u, out, out2, count); }},
      {"hvp_H", plugin.has_hamiltonian_hessian_products(),
       [&] { model.hvp_H(HamiltonianForm::TTV, x, u, u, x, out, out2, count); }},
      {"grad_T", !general, [&] { model.grad_T(x, out, count); }},
      {"grad_V", !general, [&] { model.grad_V(x, out, count); }},
      {"hessian_T", plugin.has_hessians() && hessians_fit, [&] { model.hessian_T(x, matrix, count); }},
      {"hessian_V", plugin.has_hessians() && hessians_fit, [&] { model.hessian_V(x, matrix, count); }},
      {"hvp_T", plugin.has_hessian_vector_products(), [&] { model.hvp_T(x, u, out, count); }},
      {"hvp_V", plugin.has_hessian_vector_products(), [&] { model.hvp_V(x, u, out, count); }},
      {"d3T", plugin.has_third_derivatives(), [&] { model.d3T(x, u, out, count); }},
      {"d3V", plugin.has_third_derivatives(), [&] { model.d3V(x, u, out, count); }},
      {"grad_K", plugin.has_K(), [&] { model.grad_K(x, out, count); }},
      {"grad_U", plugin.has_U(), [&] { model.grad_U(x, out, count); }},
  };
  std::string text;
  if (metadata.contains("automatic_differentiation") && metadata["automatic_differentiation"].is_string())
    text += "  automatic:   " + metadata["automatic_differentiation"].get<std::string>() + "\n";
  text += "  cost per state of one call (" + std::to_string(count) +
          " states at random points in [-1, 1]^n, default parameters, measured now on this machine):\n";
  for (const Function& function : functions) {
    if (!function.present) continue;
    std::string line = "    " + std::string(function.name);
    line.resize(15, ' ');
    std::string kind =
        how.contains(function.name) && how[function.name].is_string() ? how[function.name].get<std::string>() : "-";
    kind.resize(11, ' ');
    line += kind;
    try {
      line += cost_text(nanoseconds_per_state(function.call, count));
    } catch (const std::exception& error) {
      line += std::string("not measured: ") + error.what();
    }
    text += line + "\n";
  }
  return text;
}

}  // namespace nonsep::host
