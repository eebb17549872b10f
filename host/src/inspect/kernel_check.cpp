// The kernel part of `nonsep inspect --check` (plugin_report.hpp, check_kernels): each kernel this processor runs
// against the evaluation path, on a few steps of the basic step (one dt for all states) and of MPE 4/3 (a step
// size per state), both forms: the catalogue's Chin schemes with one order and those that are not symplectic (the
// sums of substeps), each at its default options. The tangent kernel (chin_tangent_steps) likewise: the same steps of
// the basic step with two tangent vectors per state, states and vectors against TangentIntegrator's evaluation path.
// The Gauss-Legendre kernel (gauss_steps): a few steps of gauss 3 stages in each form the model has
// (check_gauss_kernel).
#include <algorithm>
#include <string>

#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/host/inspect/plugin_report.hpp"

namespace nonsep::host {

namespace {

// The numbers of `count` states (q, p) after `steps` steps of `spec` through `model`.
PhaseSpaceBatch run(const PluginModel& model, const IntegratorSpec& spec, std::span<const double> q,
                    std::span<const double> p, std::size_t count, double dt, std::uint64_t steps) {
  PhaseSpaceBatch x(model.dimension(), count);
  std::copy_n(q.begin(), x.size(), x.q().begin());
  std::copy_n(p.begin(), x.size(), x.p().begin());
  Integrator integrator(spec);
  integrator.step_n(model, x, dt, steps);
  return x;
}

// `steps` steps of `spec` through the evaluation path (`model`) and through `kernel` from the same states: their
// differences into `difference`, or the model's failure into `failure`.
void compare_runs(const PluginModel& model, const PluginModel& kernel, const IntegratorSpec& spec,
                  std::span<const double> q, std::span<const double> p, std::size_t count, double dt,
                  std::uint64_t steps, PathDifference& difference, std::string& failure) {
  try {
    const PhaseSpaceBatch expected = run(model, spec, q, p, count, dt, steps);
    const PhaseSpaceBatch found = run(kernel, spec, q, p, count, dt, steps);
    for (std::size_t i = 0; i < expected.size(); ++i) {
      difference.add(expected.q()[i], found.q()[i]);
      difference.add(expected.p()[i], found.p()[i]);
    }
  } catch (const ModelError& error) {
    failure = error.what();
  }
}

// What a comparison with the evaluation path found, in words (judged by `result` against `tolerance`).
std::string verdict(PathCheck& result, const PathDifference& difference, const std::string& failure, double tolerance,
                    const char* rounding) {
  if (!failure.empty()) return "not compared: the model failed at the sample points (" + failure + ")";
  if (difference.identical) return "identical to the evaluation path bit for bit";
  return result.judge(difference, tolerance, "the evaluation path", rounding);
}

constexpr const char* other_rounding =
    "relative to max(1, |x|); fused multiply-add or other compiler flags round differently";

// The numbers of `count` states and two tangent vectors each (the unit vectors of dq_0 and dp_0) after `steps` basic
// steps of `form`, through the tangent kernel (`kernel` true; nothing when the plugin has none) or the evaluation path:
// q, p, then the vectors' dq and dp.
std::vector<double> tangent_run(const PluginModel& model, HamiltonianForm form, std::span<const double> q,
                                std::span<const double> p, std::size_t count, double dt, std::uint64_t steps,
                                bool kernel) {
  const std::size_t n = model.dimension();
  PhaseSpaceBatch x(n, count), vectors(n, 2 * count);
  std::copy_n(q.begin(), x.size(), x.q().begin());
  std::copy_n(p.begin(), x.size(), x.p().begin());
  for (std::size_t b = 0; b < count; ++b) {
    vectors.q()[2 * b * n] = 1.0;
    vectors.p()[(2 * b + 1) * n] = 1.0;
  }
  IntegratorSpec spec;
  spec.form = form;
  TangentIntegrator integrator(spec, 2);
  if (kernel) {
    if (!integrator.step_kernel_n(model, x, vectors, dt, steps)) return {};
  } else {
    for (std::uint64_t step = 0; step < steps; ++step) integrator.step(model, x, vectors, dt);
  }
  std::vector<double> numbers(x.q().begin(), x.q().end());
  numbers.insert(numbers.end(), x.p().begin(), x.p().end());
  numbers.insert(numbers.end(), vectors.q().begin(), vectors.q().end());
  numbers.insert(numbers.end(), vectors.p().begin(), vectors.p().end());
  return numbers;
}

// The schemes the check steps, in catalogue order: the basic step and the multi-product expansion.
std::vector<IntegratorSpec> checked_schemes() {
  std::vector<IntegratorSpec> specs;
  for (const Scheme& scheme : scheme_catalogue())
    if (scheme.family == "chin" && (scheme.highest_order_index == 1 || !scheme.symplectic))
      specs.push_back(default_spec(scheme));
  return specs;
}

// "basic and mpe 4/3": each scheme with its order unless it has only one.
std::string checked_schemes_text(const std::vector<IntegratorSpec>& specs) {
  std::string text;
  for (std::size_t i = 0; i < specs.size(); ++i) {
    text += i == 0 ? "" : i + 1 == specs.size() ? " and " : ", ";
    text += specs[i].scheme;
    if (find_scheme(specs[i].scheme)->highest_order_index > 1)
      text += " " + Integrator::describe(specs[i]).order.to_string();
  }
  return text;
}

}  // namespace

PathCheck check_kernels(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                        std::span<const double> p, std::size_t count, double tolerance) {
  PathCheck result;
  const KernelChoice& kernels = plugin.kernels();
  if (!kernels.present) {
    result.text = "kernels: none (the evaluation path steps this plugin)\n";
    return result;
  }
  if (!kernels.chosen && kernels.version != chin_kernel_version) {
    result.text = "kernels: not checked: " + kernels.note + "\n";
    return result;
  }
  constexpr double dt = 1e-3;
  constexpr std::uint64_t steps = 8;
  for (std::size_t index = 0; index < kernels.instruction_sets.size(); ++index) {
    const std::string& name = kernels.instruction_sets[index];
    const PluginModel kernel = model.with_kernel(index);
    if (!kernel.has_kernel()) {
      result.text += "kernel " + name + ": not checked (this processor does not run it)\n";
      continue;
    }
    PathDifference difference;
    std::string failure;
    for (IntegratorSpec spec : checked_schemes())
      for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
        spec.form = form;
        compare_runs(model, kernel, spec, q, p, count, dt, steps, difference, failure);
      }
    result.text += "kernel " + name + ": " + verdict(result, difference, failure, tolerance, other_rounding) +
                   (index == kernels.chosen ? " [used by runs]" : "") + "\n";
    if (!model.has_hessian_vector_products()) continue;
    PathDifference tangent_difference;
    bool tangent_kernel = true;
    failure.clear();
    for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) try {
        const std::vector<double> expected = tangent_run(model, form, q, p, count, dt, steps, false);
        const std::vector<double> found = tangent_run(kernel, form, q, p, count, dt, steps, true);
        tangent_kernel = !found.empty();
        for (std::size_t i = 0; i < found.size(); ++i) tangent_difference.add(expected[i], found[i]);
      } catch (const ModelError& error) {
        failure = error.what();
      }
    if (!tangent_kernel) continue;  // a plugin of ABI version 4, or one without chin_tangent_steps
    result.text += "tangent kernel " + name +
                   " (basic, 2 vectors): " + verdict(result, tangent_difference, failure, tolerance, other_rounding) +
                   "\n";
  }
  result.text = "kernels (" + std::to_string(steps) + " steps of " + checked_schemes_text(checked_schemes()) + ", dt " +
                std::to_string(dt).substr(0, 5) + ", TTV and VVT, " + std::to_string(count) + " states):\n" +
                result.text;
  return result;
}

PathCheck check_gauss_kernel(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                             std::span<const double> p, std::size_t count, double tolerance) {
  PathCheck result;
  const PluginModel kernel = model.with_kernel();
  if (!kernel.has_gauss_kernel()) {
    result.text = "Gauss-Legendre kernel: none (the evaluations step gauss and implicit_midpoint)\n";
    return result;
  }
  constexpr double dt = 1e-3;
  constexpr std::uint64_t steps = 8;
  IntegratorSpec spec = spec_of_order(*find_scheme("gauss"), Fraction(6));
  PathDifference difference;
  std::string failure;
  const std::uint64_t calls_before = kernel.kernel_calls();
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    if (form == HamiltonianForm::VVT && plugin.general_hamiltonian()) continue;
    spec.form = form;
    compare_runs(model, kernel, spec, q, p, count, dt, steps, difference, failure);
  }
  result.text = "Gauss-Legendre kernel (" + std::to_string(steps) + " steps of gauss 3 stages, dt " +
                std::to_string(dt).substr(0, 5) + (plugin.general_hamiltonian() ? "" : ", TTV and VVT") + ", " +
                std::to_string(count) + " states): ";
  if (failure.empty() && kernel.kernel_calls() == calls_before)
    result.text += "not compared: every step went through the evaluations (an iteration did not converge)\n";
  else
    result.text += verdict(result, difference, failure, tolerance,
                           "relative to max(1, |x|); the plugin was compiled with other flags than the host") +
                   "\n";
  return result;
}

}  // namespace nonsep::host
