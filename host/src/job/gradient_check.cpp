// The check of a plugin's gradients at a job's initial states (load_model, so `nonsep run` and `nonsep validate`):
// for n > 1 the Hessians of T and V symmetric (the gradients are gradients of functions: a formula's dT and dV are
// checked this way), and grad T and grad V against 5-point finite differences of value_T and value_V (the SDK's
// derivative checker, nonsep/derivative_checker.hpp), at up to gradient_check_states states spread evenly over the
// ensemble, on an instance of the plugin of its own with the state's parameters (a sweep's states, each with its own
// parameter set's; the run's instance, and any call counts it keeps, are left alone).
// A model given by H itself (plugin ABI version 6): grad_H against the differences of value_H at the states (q, p).
#include <algorithm>
#include <cmath>
#include <exception>

#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/checker.hpp"

namespace nonsep::host {

namespace {

constexpr std::size_t gradient_check_states = 16;
// The largest dimension checked: each state's stencil holds 4n points of n numbers.
constexpr std::size_t gradient_check_largest_dimension = 512;
// Looser than `inspect --check`'s 1e-6: a smooth model's gradients agree with the differences to about 1e-10, a
// wrong one differs by far more; what lies between is left to `inspect --check`.
constexpr double gradient_check_tolerance = 1e-4;

std::string vector_text(const std::vector<double>& x) {
  std::string text;
  for (double value : x) text += (text.empty() ? "" : ", ") + DerivativeCheckReport::scientific(value, 6);
  return "(" + text + ")";
}

// The Hessian of T (kinetic) or V at `x`, which must be symmetric: it is the Jacobian of the gradient, and a gradient
// that is not one of any function (a formula's dT or dV, a gradient template) has an asymmetric Jacobian. An issue
// at the first asymmetric pair beyond rounding; false then.
bool check_symmetry(const LoadedJob& loaded, const PluginModel& model, bool kinetic, const std::vector<double>& x,
                    std::size_t state, std::vector<JobIssue>& issues) {
  const std::size_t n = x.size();
  std::vector<double> hessian(n * n);
  try {
    kinetic ? model.hessian_T(x, hessian, 1) : model.hessian_V(x, hessian, 1);
  } catch (const std::exception&) {
    return true;  // the model cannot be evaluated there: the run reports it for that trajectory
  }
  const char letter = kinetic ? 'p' : 'q';
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double a = hessian[i * n + j], b = hessian[j * n + i];  // d g_i / dx_j, d g_j / dx_i
      if (!std::isfinite(a) || !std::isfinite(b) || std::abs(a - b) <= 1e-8 * std::max({1.0, std::abs(a), std::abs(b)}))
        continue;
      const std::string at = " at initial state " + std::to_string(state) + " (" + letter + " = " + vector_text(x) +
                             ") is not symmetric: ";
      const auto& formula = loaded.job.formula;
      const bool given = formula && !(kinetic ? formula->t_gradient : formula->v_gradient).empty();
      const std::string key = kinetic ? "dT" : "dV";
      const auto d = [&](std::size_t component, std::size_t by, double value) {
        return "d " + key + "[" + std::to_string(component) + "] / d" + letter + std::to_string(by) + " = " +
               DerivativeCheckReport::scientific(value, 6);
      };
      if (given)
        issues.push_back({formula->file.empty() ? "/model/formula/" + key : formula->file.string() + "#/" + key,
                          "the Jacobian of " + key + at + d(i, j, a) + " but " + d(j, i, b) + ", so " + key +
                              " is not the gradient of any function",
                          std::string("the gradient of a function ") + (kinetic ? "T(p)" : "V(q)") +
                              " (whose Jacobian, the Hessian, is symmetric): check the components, or give " +
                              (kinetic ? "T" : "V") + " itself"});
      else
        issues.push_back({"/model/plugin",
                          "the plugin '" + loaded.plugin.name() + "', whose " + (kinetic ? "hessian_T" : "hessian_V") +
                              at + "[" + std::to_string(i) + "][" + std::to_string(j) +
                              "] = " + DerivativeCheckReport::scientific(a, 6) + " but [" + std::to_string(j) + "][" +
                              std::to_string(i) + "] = " + DerivativeCheckReport::scientific(b, 6),
                          "a plugin whose gradients are gradients of functions (their Jacobians, the Hessians, are "
                          "symmetric); `nonsep inspect " +
                              loaded.plugin.path().string() + " --check` compares them with finite differences"});
      return false;
    }
  return true;
}

}  // namespace

void check_gradients_at_initial_states(const LoadedJob& loaded, std::vector<JobIssue>& issues) {
  const InitialStates& initial = loaded.job.initial;
  const std::size_t n = loaded.model.dimension();
  if (n == 0 || n > gradient_check_largest_dimension || initial.count == 0 || initial.q.size() != initial.count * n)
    return;
  std::optional<PluginModel> own;  // of the parameter set `own_set` (a sweep: each state's own set's)
  std::size_t own_set = 0;
  const std::size_t checked = std::min(initial.count, gradient_check_states);
  // The instance of state `state`'s parameter set (created anew when the set changes); false when the plugin refuses
  // it a second time, which is the plugin's to explain.
  const auto own_instance = [&](std::size_t state) {
    const std::size_t set = initial.parameter_set.empty() ? 0 : initial.parameter_set[state];
    if (own && set == own_set) return true;
    try {
      own.emplace(loaded.plugin.create(loaded.job.parameter_set(set)));
      own_set = set;
      return true;
    } catch (const std::exception&) {
      return false;
    }
  };
  if (loaded.plugin.general_hamiltonian()) {
    DerivativeCheckOptions options;
    options.random_points = 0;
    options.tolerance = gradient_check_tolerance;
    options.check_hessian_vector_products = false;
    for (std::size_t k = 0; k < checked; ++k) {
      const std::size_t state = k * initial.count / checked;
      if (!own_instance(state)) return;
      std::vector<double> z(initial.q.begin() + static_cast<std::ptrdiff_t>(state * n),
                            initial.q.begin() + static_cast<std::ptrdiff_t>((state + 1) * n));
      z.insert(z.end(), initial.p.begin() + static_cast<std::ptrdiff_t>(state * n),
               initial.p.begin() + static_cast<std::ptrdiff_t>((state + 1) * n));
      options.points.assign(1, std::move(z));
      DerivativeCheckReport report;
      try {
        report = check_hamiltonian_derivatives(*own, options);
      } catch (const std::exception&) {
        return;  // the model cannot be evaluated there: the run reports it for that trajectory
      }
      for (const DerivativeMismatch& mismatch : report.mismatches) {
        if (!std::isfinite(mismatch.computed) || !std::isfinite(mismatch.finite_difference)) continue;
        const std::string component = mismatch.component < n ? "dH/dq" + std::to_string(mismatch.component)
                                                             : "dH/dp" + std::to_string(mismatch.component - n);
        issues.push_back({"/model/plugin",
                          "the plugin '" + loaded.plugin.name() + "', whose grad_H (" + component +
                              ") at initial state " + std::to_string(state) +
                              " ((q, p) = " + vector_text(mismatch.point) + ") is " +
                              DerivativeCheckReport::scientific(mismatch.computed, 6) +
                              " where the finite difference of value_H gives " +
                              DerivativeCheckReport::scientific(mismatch.finite_difference, 6),
                          "a plugin whose grad_H is the derivative of its value_H (a wrong gradient makes every step "
                          "wrong); `nonsep inspect " +
                              loaded.plugin.path().string() + " --check` compares them at sample points"});
        return;
      }
    }
    return;
  }
  for (std::size_t k = 0; k < checked; ++k) {
    const std::size_t state = k * initial.count / checked;
    if (!own_instance(state)) return;
    const auto at = [&](const std::vector<double>& x) {
      return std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(state * n),
                                 x.begin() + static_cast<std::ptrdiff_t>((state + 1) * n));
    };
    for (const bool kinetic : {true, false}) {
      if (n > 1 && loaded.plugin.has_hessians() &&
          !check_symmetry(loaded, *own, kinetic, at(kinetic ? initial.p : initial.q), state, issues))
        return;
      if (!loaded.plugin.has_values()) continue;
      DerivativeCheckOptions options;
      options.random_points = 0;
      options.points = {at(kinetic ? initial.p : initial.q)};
      options.tolerance = gradient_check_tolerance;
      options.check_hessians = options.check_third_derivatives = options.check_hessian_vector_products = false;
      options.check_kinetic = kinetic;
      options.check_potential = !kinetic;
      DerivativeCheckReport report;
      try {
        report = check_derivatives(*own, options);
      } catch (const std::exception&) {
        continue;  // the model cannot be evaluated there: the run reports it for that trajectory
      }
      for (const DerivativeMismatch& mismatch : report.mismatches) {
        // Values or gradients that overflow or leave the model's domain say nothing about the gradient's formula.
        if (!std::isfinite(mismatch.computed) || !std::isfinite(mismatch.finite_difference)) continue;
        const std::string values = kinetic ? "value_T" : "value_V";
        issues.push_back(
            {"/model/plugin",
             "the plugin '" + loaded.plugin.name() + "', whose " + mismatch.function + "[" +
                 std::to_string(mismatch.component) + "] at initial state " + std::to_string(state) + " (" +
                 (kinetic ? "p" : "q") + " = " + vector_text(mismatch.point) + ") is " +
                 DerivativeCheckReport::scientific(mismatch.computed, 6) + " where the finite difference of " + values +
                 " gives " + DerivativeCheckReport::scientific(mismatch.finite_difference, 6),
             "a plugin whose gradients are the derivatives of its values (a wrong gradient makes every step "
             "wrong); `nonsep inspect " +
                 loaded.plugin.path().string() + " --check --points-from " + loaded.job.file.string() +
                 "` lists every mismatch"});
        return;
      }
    }
  }
}

}  // namespace nonsep::host
