// The hvp_H part of `nonsep inspect --check` (plugin_report.hpp, check_hamiltonian_products): a product-form plugin's
// directional derivative of grad H against central differences of grad H along the same tangent, in both forms. Its
// fourth derivatives of T and V are checked nowhere else, and a model may write them out (d4T, d4V).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"

namespace nonsep::host {

PathCheck check_hamiltonian_products(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                                     std::span<const double> p, std::size_t count, double step, double tolerance) {
  PathCheck result;
  if (plugin.general_hamiltonian() || !plugin.has_hamiltonian_hessian_products() || !plugin.has_third_derivatives())
    return result;
  const std::size_t n = model.dimension(), size = count * n;
  std::mt19937_64 random(2009);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> dq(size), dp(size);
  for (auto* v : {&dq, &dp})
    for (double& x : *v) x = uniform(random);
  // Five-point differences of grad H along (dq, dp), each state its own h = step max(1, |(q, p)|_inf).
  std::vector<double> h(count);
  for (std::size_t b = 0; b < count; ++b) {
    double scale = 1.0;
    for (std::size_t i = 0; i < n; ++i) scale = std::max({scale, std::abs(q[b * n + i]), std::abs(p[b * n + i])});
    h[b] = step * scale;
  }
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    const std::string line = std::string("hvp_H (") + (form == HamiltonianForm::TTV ? "TTV" : "VVT") +
                             ") against differences of grad H, " + std::to_string(count) + " states: ";
    std::vector<double> out_q(size), out_p(size), differenced_q(size, 0.0), differenced_p(size, 0.0);
    try {
      constexpr std::pair<double, double> stencil[] = {{-2.0, 1.0}, {-1.0, -8.0}, {1.0, 8.0}, {2.0, -1.0}};
      for (const auto& [multiple, weight] : stencil) {
        std::vector<double> at_q(size), at_p(size), g_q(size), g_p(size);
        for (std::size_t k = 0; k < size; ++k) {
          at_q[k] = q[k] + multiple * h[k / n] * dq[k];
          at_p[k] = p[k] + multiple * h[k / n] * dp[k];
        }
        HamiltonianGradient(form).evaluate(model, at_q, at_p, g_q, g_p, count);
        for (std::size_t k = 0; k < size; ++k) {
          differenced_q[k] += weight * g_q[k] / (12.0 * h[k / n]);
          differenced_p[k] += weight * g_p[k] / (12.0 * h[k / n]);
        }
      }
    } catch (const ModelError& error) {
      result.text += line + "not compared (grad H: " + error.what() + ")\n";
      continue;
    }
    try {
      model.hvp_H(form, q, p, dq, dp, out_q, out_p, count);
    } catch (const ModelError& error) {  // grad H evaluates around the points, so hvp_H should at them
      result.passed = false;
      result.text += line + "FAILED: hvp_H failed where grad H evaluates (" + error.what() + ")\n";
      continue;
    }
    PathDifference difference;
    for (std::size_t k = 0; k < size; ++k) {
      difference.add(differenced_q[k], out_q[k]);
      difference.add(differenced_p[k], out_p[k]);
    }
    result.text += line + result.judge(difference, tolerance, "the differences", "relative to max(1, |d|)") + "\n";
  }
  return result;
}

}  // namespace nonsep::host
