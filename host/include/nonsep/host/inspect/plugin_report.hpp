#pragma once
// What `nonsep inspect` and `nonsep models` print, and the derivative check of `nonsep inspect --check`.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host {

// Human-readable metadata: identity, file, Hamiltonian, dimension, capabilities, thread safety and a table of
// parameters with type, default, range, unit and description. Several lines, each ending in '\n'.
std::string describe_plugin(const Plugin& plugin);

// `nonsep inspect`'s costs: how the derivatives are obtained (the metadata's "automatic_differentiation", when the
// plugin says) and, for each derivative function the plugin has, its time per state of one call: the function
// called on a batch of up to 32 states (seeded points in [-1, 1]^n) for about 10 ms. A function that throws there
// shows "not measured: <message>"; Hessians are left out above n = 1024. Several lines, each ending in '\n'.
std::string describe_derivative_costs(const Plugin& plugin, const PluginModel& model);

// One line for `nonsep models`: "name  version  dimension  path  description", or "path  error" for a file that
// failed to load. No trailing newline.
std::string describe_discovered(const DiscoveredPlugin& discovered);

// `nonsep inspect --check`: the SDK's derivative checker (nonsep/derivative_checker.hpp: 5-point finite
// differences, tolerance relative to max(1, |finite difference|)) on a plugin instance, checking grad T and grad V
// against value_T / value_V when the plugin has values, the Hessians against the gradients when it has Hessians,
// and d3T, d3V against the Hessians when it has both; plus batch consistency: one call on all points gives the
// same numbers, bit for bit, as one call per point (the runner relies on it to retire states from an ensemble
// without changing the others; NaN in both agrees); plus, for a plugin declaring "thread_safe": true, two
// instances used at once on two threads give the numbers of one instance on one thread (the runner gives each
// worker thread its own instance; reported as skipped for "thread_safe": false); plus check_kernels (below) on
// the sample points.
//
// Sample points: `random_points` seeded points in [box_low, box_high]^n, each used as p for the T functions and
// as q for the V functions; then `p_points` for the T functions only and `q_points` for the V functions only (a
// job's initial states, which lie in the model's domain where a box may not).
struct DerivativeCheckSettings {
  double box_low = -1.5, box_high = 1.5;
  std::size_t random_points = 16;
  std::vector<std::vector<double>> p_points, q_points;  // each of the model's dimension
  double tolerance = 1e-6;
};

// Throws nonsep::ModelError when the plugin fails to evaluate at a sample point, std::bad_alloc when the check's
// buffers do not fit in memory (they grow as n^2 per point, n^3 with third derivatives).
struct DerivativeCheck {
  bool passed = true;
  std::size_t comparisons = 0;  // derivative entries compared with finite differences; 0: nothing was checked
  std::string text;             // several lines, each ending in '\n'; the last says "passed" or "FAILED"
};
DerivativeCheck check_derivatives(const PluginModel& model, const Plugin& plugin,
                                  const DerivativeCheckSettings& settings = {});

// The numbers of one comparison of two ways to them: the largest difference of `found` from `expected`, relative to
// max(1, |expected|); whether every pair is the same number (bit for bit, or both NaN); whether none is non-finite
// on one side only.
struct PathDifference {
  double largest = 0.0;
  bool identical = true, comparable = true;
  void add(double expected, double found);
};

// A comparison of two ways to the same numbers (the kernels and the evaluation path; a plugin's own energy and the
// core's rule): the largest difference found, its lines of the report, and whether it passed.
struct PathCheck {
  bool passed = true;
  double largest_difference = 0.0;
  std::string text;  // lines ending in '\n'
  // The verdict on `difference` against `reference` (what the other way is called), for a line of the report:
  // "largest difference from REFERENCE X (RELATIVE_TO)", failed above `tolerance` or when not comparable.
  std::string judge(const PathDifference& difference, double tolerance, const std::string& reference,
                    const std::string& relative_to);
};

// The kernel part of the check: each of the plugin's kernels this processor runs against the evaluation path on
// `count` states (q, p: count*n numbers each), a few steps of the basic step and of MPE 4/3 in both forms. Bit for
// bit equal for a plugin built with the host's flags; a plugin built with other flags (-march=native, -ffast-math)
// or a wider instruction set (fused multiply-add) may round differently: the largest difference, relative to
// max(1, |x|), is reported, and above `tolerance` (or non-finite on one side only) the check fails. A model
// failing at the points is reported, not a failure.
PathCheck check_kernels(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                        std::span<const double> p, std::size_t count, double tolerance);

// The Gauss-Legendre kernel (plugin_abi.h gauss_steps; nothing when the plugin has none) against the evaluation path
// on `count` states, a few steps of gauss 3 stages in each form the model has, judged as check_kernels.
PathCheck check_gauss_kernel(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                             std::span<const double> p, std::size_t count, double tolerance);

// The plugin's own product term of H (plugin_abi.h energy_TTV, energy_VVT; nothing when it has neither) against H
// from its Hessian-vector products or Hessians at the count states (q, p): the largest difference relative to
// max(1, |H|) is reported, and above `tolerance` (or non-finite on one side only) the check fails.
PathCheck check_product_energy(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                               std::span<const double> p, std::size_t count, double tolerance);

// A product-form plugin's hvp_H (nothing for a general one, or one without hvp_H or third derivatives) against
// five-point central differences of grad H along a seeded tangent per state, h = step max(1, |(q, p)|_inf), in both
// forms at the count states (q, p): the largest difference relative to max(1, |difference|) is reported, and above
// `tolerance` (or non-finite on one side only) the check fails.
PathCheck check_hamiltonian_products(const PluginModel& model, const Plugin& plugin, std::span<const double> q,
                                     std::span<const double> p, std::size_t count, double step, double tolerance);

// The number of bytes the check of a model of dimension n with these settings holds at its largest (an estimate
// within a small factor, computed without overflow: saturates at the largest double).
double derivative_check_bytes(std::size_t n, bool third_derivatives, const DerivativeCheckSettings& settings);

}  // namespace nonsep::host
