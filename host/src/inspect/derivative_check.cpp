// `nonsep inspect --check`'s derivative check (plugin_report.hpp): the SDK's derivative checker on a plugin
// instance, batch consistency and, for a thread-safe plugin, two instances on two threads.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <span>
#include <thread>
#include <vector>

#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/plugin_abi.h"

namespace nonsep::host {

namespace {

std::string point_text(const char* variable, std::span<const double> x) {
  std::string text = std::string(variable) + " = (";
  for (std::size_t i = 0; i < x.size(); ++i) text += (i ? ", " : "") + format_number(x[i]);
  return text + ")";
}

// Numbers in [low, high] from a 64-bit LCG: the same on every machine.
std::vector<double> sample_points(std::size_t size, std::uint64_t state, double low, double high) {
  std::vector<double> at(size);
  for (double& x : at) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    x = low + (high - low) * (static_cast<double>(state >> 11) / 9007199254740992.0);
  }
  return at;
}

// Bit for bit the same, or both NaN (a point outside the model's domain gives NaN alone and in a batch).
bool same_number(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0 || (std::isnan(a) && std::isnan(b));
}

// The batched functions the plugin has, as (model, x, u, out, count) calls; u is read by d3T, d3V, the products and
// the energies (as p).
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
  if (plugin.general_hamiltonian()) {
    // H and its gradient at q with the directions as the momenta; grad_H's dH/dq and dH/dp side by side per state.
    std::vector<EvaluationFunction> general{
        {"value_H", "q", 1, [](M m, X q, X p, Out out, C c) { m.value_H(q, p, out, c); }},
        {"grad_H", "q", 2 * n, [](M m, X q, X p, Out out, C c) {
           const std::size_t size = q.size() < p.size() ? q.size() : p.size(), per = c == 0 ? 0 : size / c;
           std::vector<double> dq(c * per), dp(c * per);
           m.grad_H(q, p, dq, dp, c);
           for (std::size_t b = 0; b < c; ++b)
             for (std::size_t i = 0; i < per; ++i) {
               out[b * 2 * per + i] = dq[b * per + i];
               out[b * 2 * per + per + i] = dp[b * per + i];
             }
         }}};
    return general;
  }
  std::vector<EvaluationFunction> functions{{"grad_T", "p", n, [](M m, X x, X, Out out, C c) { m.grad_T(x, out, c); }},
                                            {"grad_V", "q", n, [](M m, X x, X, Out out, C c) { m.grad_V(x, out, c); }}};
  if (plugin.has_hessians()) {
    functions.push_back({"hessian_T", "p", n * n, [](M m, X x, X, Out out, C c) { m.hessian_T(x, out, c); }});
    functions.push_back({"hessian_V", "q", n * n, [](M m, X x, X, Out out, C c) { m.hessian_V(x, out, c); }});
  }
  if (plugin.has_third_derivatives()) {
    functions.push_back({"d3T", "p", n, [](M m, X x, X u, Out out, C c) { m.d3T(x, u, out, c); }});
    functions.push_back({"d3V", "q", n, [](M m, X x, X u, Out out, C c) { m.d3V(x, u, out, c); }});
  }
  if (plugin.has_hessian_vector_products()) {
    functions.push_back({"hvp_T", "p", n, [](M m, X x, X v, Out out, C c) { m.hvp_T(x, v, out, c); }});
    functions.push_back({"hvp_V", "q", n, [](M m, X x, X v, Out out, C c) { m.hvp_V(x, v, out, c); }});
  }
  // The product term of H: at q, with the directions as the momenta.
  if (plugin.has_product_energy(HamiltonianForm::TTV))
    functions.push_back({"energy_TTV", "q", 1,
                         [](M m, X q, X p, Out out, C c) { m.product_energy(HamiltonianForm::TTV, q, p, out, c); }});
  if (plugin.has_product_energy(HamiltonianForm::VVT))
    functions.push_back({"energy_VVT", "q", 1,
                         [](M m, X q, X p, Out out, C c) { m.product_energy(HamiltonianForm::VVT, q, p, out, c); }});
  return functions;
}

// The sample points (flat, n numbers each) and directions of the consistency checks: for the T functions (p) and
// for the V functions (q).
struct Samples {
  struct Points {
    std::size_t count = 0;
    std::vector<double> at, directions;
  };
  Points p, q;
  Samples(std::size_t n, const DerivativeCheckSettings& settings) {
    const auto random =
        sample_points(settings.random_points * n, 0x9E3779B97F4A7C15ull, settings.box_low, settings.box_high);
    for (auto [points, given] : {std::pair{&p, &settings.p_points}, std::pair{&q, &settings.q_points}}) {
      points->at = random;
      for (const auto& x : *given) points->at.insert(points->at.end(), x.begin(), x.end());
      points->count = n == 0 ? 0 : points->at.size() / n;
      points->directions = sample_points(points->at.size(), 0xD1B54A32D192ED03ull, -1.5, 1.5);
    }
  }
  const Points& of(const EvaluationFunction& function) const { return function.variable[0] == 'p' ? p : q; }
};

// One call on all points must give, bit for bit, what one call per point gives: the runner steps an ensemble as
// one batch and retires states from it, which is only invisible to the others if states do not interact.
// Returns "" or a description of the first difference.
std::string batch_difference(const PluginModel& model, const Plugin& plugin, const Samples& samples) {
  const std::size_t n = model.dimension();
  for (const auto& function : evaluation_functions(plugin, n)) {
    const Samples::Points& sample = samples.of(function);
    const std::size_t points = sample.count;
    if (points == 0) continue;
    std::vector<double> batch(points * function.width), alone(function.width);
    function.evaluate(model, sample.at, sample.directions, batch, points);
    for (std::size_t b = 0; b < points; ++b) {
      const auto x = std::span<const double>(sample.at).subspan(b * n, n);
      function.evaluate(model, x, std::span<const double>(sample.directions).subspan(b * n, n), alone, 1);
      for (std::size_t i = 0; i < function.width; ++i)
        if (!same_number(alone[i], batch[b * function.width + i]))
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
  const auto functions = evaluation_functions(plugin, model.dimension());
  std::vector<std::vector<double>> reference;
  for (const auto& function : functions) {
    const Samples::Points& sample = samples.of(function);
    reference.emplace_back(sample.count * function.width);
    function.evaluate(model, sample.at, sample.directions, reference.back(), sample.count);
  }
  const PluginModel second = plugin.create(model.parameters());
  std::string found[2];
  std::exception_ptr failure[2];
  auto work = [&](int thread, const PluginModel& instance) {
    try {
      for (std::size_t round = 0; round < rounds && found[thread].empty(); ++round)
        for (std::size_t f = 0; f < functions.size() && found[thread].empty(); ++f) {
          const Samples::Points& sample = samples.of(functions[f]);
          if (sample.count == 0) continue;
          std::vector<double> out(reference[f].size());
          functions[f].evaluate(instance, sample.at, sample.directions, out, sample.count);
          for (std::size_t k = 0; k < out.size(); ++k)
            if (!same_number(out[k], reference[f][k])) {
              found[thread] = std::string(functions[f].name) + "[" + std::to_string(k) + "] of a batch of " +
                              std::to_string(sample.count) + " is " + format_number(reference[f][k]) +
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

double derivative_check_bytes(std::size_t n, bool third_derivatives, const DerivativeCheckSettings& settings) {
  const double dimension = static_cast<double>(n);
  const double points =
      static_cast<double>(settings.random_points + std::max(settings.p_points.size(), settings.q_points.size()));
  // The SDK's stencils (4n points of n numbers, their gradients, n x n Hessians; 4n Hessians for the third
  // derivatives), the reference results of the thread check and each thread's copy (all points, every function).
  const double numbers = 9.0 * dimension * dimension +
                         (third_derivatives ? 4.0 * dimension * dimension * dimension : 0.0) +
                         6.0 * points * (4.0 * dimension + 2.0 * dimension * dimension);
  return 8.0 * numbers;
}

DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin,
                                  const DerivativeCheckSettings& settings) {
  const std::size_t n = model.dimension();
  const Samples samples(n, settings);
  DerivativeCheck result;
  DerivativeCheckReport report;
  std::string points;
  if (settings.random_points > 0)
    points = std::to_string(settings.random_points) + " random in [" +
             DerivativeCheckReport::scientific(settings.box_low, 3) + ", " +
             DerivativeCheckReport::scientific(settings.box_high, 3) + "]^" + std::to_string(n);
  if (plugin.general_hamiltonian()) {
    // A model given by H: grad_H against differences of value_H and hvp_H against differences of grad_H, at the
    // phase points (q_k, p_k) of the samples.
    DerivativeCheckOptions options;
    options.tolerance = settings.tolerance;
    options.random_points = 0;
    options.check_hessian_vector_products = plugin.has_hamiltonian_hessian_products();
    for (std::size_t k = 0; k < std::min(samples.q.count, samples.p.count); ++k) {
      std::vector<double> z(samples.q.at.begin() + static_cast<std::ptrdiff_t>(k * n),
                            samples.q.at.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      z.insert(z.end(), samples.p.at.begin() + static_cast<std::ptrdiff_t>(k * n),
               samples.p.at.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      options.points.push_back(std::move(z));
    }
    report = nonsep::check_hamiltonian_derivatives(model, options);
    if (!settings.p_points.empty())
      points += (points.empty() ? "" : " and ") + std::to_string(settings.p_points.size()) + " given";
    result.text = "sample points (q, p): " + points + "; tolerance " +
                  DerivativeCheckReport::scientific(settings.tolerance, 3) + "\n" + report.summary();
  } else {
    DerivativeCheckOptions options;
    options.check_gradients = plugin.has_values();
    options.check_hessians = plugin.has_hessians();
    options.check_third_derivatives = plugin.has_third_derivatives() && plugin.has_hessians();
    options.check_hessian_vector_products = plugin.has_hessian_vector_products();
    options.tolerance = settings.tolerance;
    options.random_points = 0;
    // The T functions at the p points, then the V functions at the q points: two runs of the SDK's checker.
    for (const bool kinetic : {true, false}) {
      const Samples::Points& sample = kinetic ? samples.p : samples.q;
      options.check_kinetic = kinetic;
      options.check_potential = !kinetic;
      options.points.clear();
      for (std::size_t k = 0; k < sample.count; ++k)
        options.points.emplace_back(sample.at.begin() + static_cast<std::ptrdiff_t>(k * n),
                                    sample.at.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      // The separable part K(p) + U(q), where the plugin has one, at the same points (K at p, U at q).
      DerivativeCheckOptions separable = options;
      separable.check_hessian_vector_products = false;
      for (const DerivativeCheckReport& part :
           {nonsep::check_derivatives(model, options), plugin.has_K() || plugin.has_U()
                                                           ? nonsep::check_separable_derivatives(model, separable)
                                                           : DerivativeCheckReport{}}) {
        report.comparisons += part.comparisons;
        report.not_a_number += part.not_a_number;
        report.largest_error = std::max(report.largest_error, part.largest_error);
        report.mismatches.insert(report.mismatches.end(), part.mismatches.begin(), part.mismatches.end());
        report.culprits.insert(report.culprits.end(), part.culprits.begin(), part.culprits.end());
      }
    }
    if (!settings.p_points.empty())
      points +=
          (points.empty() ? "" : " and ") + std::to_string(settings.p_points.size()) + " given (p for T, q for V)";
    result.text =
        "sample points: " + points + "; tolerance " + DerivativeCheckReport::scientific(settings.tolerance, 3) + "\n";
    result.text += report.summary();
    if (!options.check_gradients) result.text += "  skipped: gradients: the plugin has no value_T/value_V\n";
    if (!options.check_hessians) result.text += "  skipped: Hessians: the plugin has no hessian_T/hessian_V\n";
    if (!options.check_third_derivatives)
      result.text += plugin.has_third_derivatives()
                         ? "  skipped: third derivatives: differencing them needs hessian_T/hessian_V\n"
                         : "  skipped: third derivatives: the plugin has no d3T/d3V\n";
    if (!options.check_hessian_vector_products)
      result.text += "  skipped: Hessian-vector products: the plugin has no hvp_T/hvp_V\n";
  }
  result.comparisons = report.comparisons;
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
    result.text +=
        "threads: skipped: the plugin declares \"thread_safe\": false (the host runs it as one instance on "
        "one thread)\n";
  }
  const std::size_t states = std::min(samples.p.count, samples.q.count);
  const PathCheck kernels = check_kernels(model, plugin, samples.q.at, samples.p.at, states, settings.tolerance);
  result.text += kernels.text;
  const PathCheck gauss = check_gauss_kernel(model, plugin, samples.q.at, samples.p.at, states, settings.tolerance);
  result.text += gauss.text;
  const PathCheck energy = check_product_energy(model, plugin, samples.q.at, samples.p.at, states, settings.tolerance);
  result.text += energy.text;
  const PathCheck products = check_hamiltonian_products(model, plugin, samples.q.at, samples.p.at, states,
                                                        DerivativeCheckOptions{}.step, settings.tolerance);
  result.text += products.text;
  result.passed = report.passed() && difference.empty() && threads.empty() && kernels.passed && gauss.passed &&
                  energy.passed && products.passed;
  if (!result.passed)
    result.text += "derivative check FAILED\n";
  else if (report.comparisons == 0)
    result.text +=
        "consistency checks passed; no derivative was compared with finite differences (the plugin has "
        "no value_T/value_V and no Hessians to difference)\n";
  else
    result.text += "derivative check passed\n";
  return result;
}

}  // namespace nonsep::host
