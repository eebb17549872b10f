#pragma once
// What `nonsep inspect` and `nonsep models` print, and the derivative check of `nonsep inspect --check`.
#include <string>

#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host {

// Human-readable metadata: identity, file, Hamiltonian, dimension, capabilities, thread safety and a table of
// parameters with type, default, range, unit and description. Several lines, each ending in '\n'.
std::string describe_plugin(const Plugin& plugin);

// One line for `nonsep models`: "name  version  dimension  path  description", or "path  error" for a file that
// failed to load. No trailing newline.
std::string describe_discovered(const DiscoveredPlugin& discovered);

// `nonsep inspect --check`: the SDK's derivative checker (nonsep/derivative_checker.hpp: 5-point finite
// differences at seeded random points in [-1.5, 1.5]^n, tolerance 1e-6 relative) on a plugin instance, checking
// grad T and grad V against value_T / value_V when the plugin has values, the Hessians against the gradients
// when it has Hessians, and d3T, d3V against the Hessians when it has both; plus batch consistency: one call on
// all points gives the same numbers, bit for bit, as one call per point (the runner relies on it to retire
// states from an ensemble without changing the others); plus, for a plugin declaring "thread_safe": true, two
// instances used at once on two threads give the numbers of one instance on one thread (the runner gives each
// worker thread its own instance; reported as skipped for "thread_safe": false).
// Throws nonsep::ModelError when the plugin fails to evaluate at a sample point.
struct DerivativeCheck {
  bool passed = true;
  std::string text;  // several lines, each ending in '\n'; the last says "passed" or "FAILED"
};
DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin);

}  // namespace nonsep::host
