#pragma once
// What `nonsep inspect` and `nonsep models` print, and the derivative check of `nonsep inspect --check`.
#include <cstddef>
#include <string>
#include <vector>

#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host {

// Human-readable metadata: identity, file, Hamiltonian, dimension, capabilities and a table of parameters with
// type, default, range, unit and description. Several lines, each ending in '\n'.
std::string describe_plugin(const Plugin& plugin);

// One line for `nonsep models`: "name  version  dimension  path  description", or "path  error" for a file that
// failed to load. No trailing newline.
std::string describe_discovered(const DiscoveredPlugin& discovered);

// The finite-difference check of a plugin instance's derivatives at a few fixed pseudo-random points in [-1, 1]^n:
// grad T and grad V against central differences of value_T / value_V (when the plugin has values), the Hessians
// against central differences of the gradients and for symmetry (when it has Hessians), and batch consistency
// (one call on all points gives the same numbers, bit for bit, as one call per point; the runner relies on it).
// A derivative passes when |analytic - numeric| <= tolerance * max(1, |analytic|).
struct DerivativeCheckLine {
  std::string what;          // "grad_T vs value_T", "hessian_V symmetry", "grad_V batch consistency", ...
  double worst_error = 0.0;  // the largest scaled error over all points and components
  bool passed = true;
  std::string note;          // why it was skipped or where it failed
};
struct DerivativeCheck {
  bool passed = true;
  std::vector<DerivativeCheckLine> lines;
};

// Throws nonsep::ModelError when the plugin fails to evaluate at a check point.
DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin, std::size_t points = 5,
                                  double tolerance = 1e-6);
std::string format_derivative_check(const DerivativeCheck& check);

}  // namespace nonsep::host
