// A test plugin written directly against the C ABI (plugin_abi.h), without the SDK, so that it can do what SDK
// plugins refuse to: return non-finite gradients. It exercises the host's handling of trajectories that diverge
// and of a plugin that fails mid-run.
//
//   T(p) = |p|^2 / 2          grad T = p,      Hess T = I
//   V(q) = sum_i q_i^4 / 4    grad V = q^3,    Hess V = diag(3 q_i^2)      H_TTV = 3 sum_i q_i^2 p_i^2
//
// grad V overflows to inf for |q| > ~5.6e102 (no finiteness check), so a state that starts there turns
// non-finite in its first step. Parameter fail_above: grad V reports NONSEP_EVALUATION_FAILED at any finite |q_i|
// above it. Parameter fail_single_above: the same, but only in a call for one state (count 1), as when the host
// locates a Poincare crossing (it steps that one state again with fractional steps), never in a block's steps of
// two or more states. Parameters nan_after and inf_after: grad V returns NaN (or +inf) in every component from its
// (n+1)-th call on (0: never). Parameter sleep_ms: every call of grad V sleeps that long first (a very slow model,
// to test that the host stays interruptible). Parameters crash_after and crash_how: from its (n+1)-th call on
// (0: never), grad V crashes the process as a faulty plugin would: crash_how 0 abort() (SIGABRT), 1 SIGSEGV,
// 2 exit(3) (the plugin's own exit status). Built four times: "blowup" (all functions), "blowup_gradients_only"
// (no values, no Hessians: no energy), "blowup_wrong_hessian" (Hess V = diag(2 q_i^2), wrong on purpose, for the
// derivative check) and "blowup_wrong_gradient" (grad V = 2 q^3, wrong on purpose while V and Hess V are right: the
// run's gradient check refuses it, and the derivative check names grad V as the culprit of Hess V's mismatches).
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <new>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "nonsep/plugin_abi.h"
#include "support/plugin_table.hpp"

#ifndef BLOWUP_NAME
#error "BLOWUP_NAME must be defined"
#endif
#if !defined(BLOWUP_WITH_HESSIANS) || !defined(BLOWUP_WRONG_HESSIAN) || !defined(BLOWUP_WRONG_GRADIENT)
#error "BLOWUP_WITH_HESSIANS, BLOWUP_WRONG_HESSIAN and BLOWUP_WRONG_GRADIENT must be defined (0 or 1)"
#endif

struct nonsep_instance {
  std::size_t dimension = 1;
  double fail_above = 1e300, fail_single_above = 1e300;
  std::uint64_t nan_after = 0, inf_after = 0, sleep_ms = 0, crash_after = 0, crash_how = 0;
  std::uint64_t grad_V_calls = 0;
  std::string last_error;
};

namespace {

[[noreturn]] void crash(std::uint64_t how) {
  if (how == 1) std::raise(SIGSEGV);  // as a stray pointer would (a null write is caught by UBSan first)
  if (how == 2) std::exit(3);
  std::abort();
}

const char* metadata() {
  static const std::string text = nlohmann::json{
      {"name", BLOWUP_NAME},
      {"version", "0.0.1"},
      {"description", "host test model: V = q^4/4 whose gradient overflows, and a switch to make it fail"},
      {"hamiltonian", "T = |p|^2/2, V = sum q_i^4/4; H_TTV = 3 sum q_i^2 p_i^2"},
      {"dimension", {{"parameter", "dimension"}}},
      {"parameters",
       {{{"name", "dimension"},
         {"type", "integer"},
         {"default", 1},
         {"minimum", 0},
         {"maximum", 1000000},
         {"description", "number of degrees of freedom (0 and huge values test the host's refusals)"}},
        {{"name", "fail_above"},
         {"type", "number"},
         {"default", 1e300},
         {"minimum", 0},
         {"unit", "length"},
         {"description", "grad V fails for any |q_i| above this"}},
        {{"name", "fail_single_above"},
         {"type", "number"},
         {"default", 1e300},
         {"minimum", 0},
         {"unit", "length"},
         {"description", "grad V fails for any |q_i| above this in a call for one state (count 1) only"}},
        {{"name", "nan_after"},
         {"type", "integer"},
         {"default", 0},
         {"minimum", 0},
         {"description", "grad V returns NaN from its (n+1)-th call on; 0: never"}},
        {{"name", "inf_after"},
         {"type", "integer"},
         {"default", 0},
         {"minimum", 0},
         {"description", "grad V returns +inf from its (n+1)-th call on; 0: never"}},
        {{"name", "crash_after"},
         {"type", "integer"},
         {"default", 0},
         {"minimum", 0},
         {"description", "grad V crashes the process from its (n+1)-th call on; 0: never"}},
        {{"name", "crash_how"},
         {"type", "integer"},
         {"default", 0},
         {"minimum", 0},
         {"maximum", 2},
         {"description", "0 abort(), 1 SIGSEGV, 2 exit(3)"}},
        {{"name", "sleep_ms"},
         {"type", "integer"},
         {"default", 0},
         {"minimum", 0},
         {"maximum", 10000},
         {"description", "each call of grad V sleeps this many milliseconds first"}}}},
      {"thread_safe", true},  // the call counters are per instance
      {"capabilities",
       {{"value_T", BLOWUP_WITH_HESSIANS == 1},
        {"value_V", BLOWUP_WITH_HESSIANS == 1},
        {"hessian_T", BLOWUP_WITH_HESSIANS == 1},
        {"hessian_V",
         BLOWUP_WITH_HESSIANS == 1}}}}.dump();
  return text.c_str();
}

nonsep_status create(const char* parameters_json, nonsep_instance** out, char* message, std::size_t size) {
  *out = nullptr;
  try {
    const auto parameters = nlohmann::json::parse(parameters_json);
    auto instance = new nonsep_instance;
    instance->dimension = parameters.value("dimension", std::size_t{1});
    instance->fail_above = parameters.value("fail_above", 1e300);
    instance->fail_single_above = parameters.value("fail_single_above", 1e300);
    instance->nan_after = parameters.value("nan_after", std::uint64_t{0});
    instance->inf_after = parameters.value("inf_after", std::uint64_t{0});
    instance->sleep_ms = parameters.value("sleep_ms", std::uint64_t{0});
    instance->crash_after = parameters.value("crash_after", std::uint64_t{0});
    instance->crash_how = parameters.value("crash_how", std::uint64_t{0});
    *out = instance;
    return NONSEP_OK;
  } catch (const std::exception& error) {
    std::snprintf(message, size, "%s", error.what());
    return NONSEP_INVALID_PARAMETERS;
  }
}

void destroy(nonsep_instance* instance) { delete instance; }
std::size_t dimension(const nonsep_instance* instance) { return instance->dimension; }

nonsep_status grad_T(nonsep_instance* instance, const double* p, double* out, std::size_t count) {
  for (std::size_t i = 0; i < count * instance->dimension; ++i) out[i] = p[i];
  return NONSEP_OK;
}
nonsep_status grad_V(nonsep_instance* instance, const double* q, double* out, std::size_t count) {
  if (instance->sleep_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(instance->sleep_ms));
  const std::uint64_t call = ++instance->grad_V_calls;
  if (instance->crash_after > 0 && call > instance->crash_after) crash(instance->crash_how);
  const bool nan = instance->nan_after > 0 && call > instance->nan_after;
  const bool inf = instance->inf_after > 0 && call > instance->inf_after;
  if (nan || inf) {
    for (std::size_t i = 0; i < count * instance->dimension; ++i)
      out[i] = nan ? std::numeric_limits<double>::quiet_NaN() : std::numeric_limits<double>::infinity();
    return NONSEP_OK;
  }
  for (std::size_t i = 0; i < count * instance->dimension; ++i) {
    if (std::isfinite(q[i]) && std::abs(q[i]) > instance->fail_above) {
      instance->last_error = "q = " + std::to_string(q[i]) + " is beyond fail_above";
      return NONSEP_EVALUATION_FAILED;
    }
    if (count == 1 && std::isfinite(q[i]) && std::abs(q[i]) > instance->fail_single_above) {
      instance->last_error = "q = " + std::to_string(q[i]) + " is beyond fail_single_above (one state)";
      return NONSEP_EVALUATION_FAILED;
    }
    out[i] = (BLOWUP_WRONG_GRADIENT ? 2.0 : 1.0) * q[i] * q[i] * q[i];
  }
  return NONSEP_OK;
}
nonsep_status value_T(nonsep_instance* instance, const double* p, double* out, std::size_t count) {
  const std::size_t n = instance->dimension;
  for (std::size_t b = 0; b < count; ++b) {
    out[b] = 0.0;
    for (std::size_t i = 0; i < n; ++i) out[b] += 0.5 * p[b * n + i] * p[b * n + i];
  }
  return NONSEP_OK;
}
nonsep_status value_V(nonsep_instance* instance, const double* q, double* out, std::size_t count) {
  const std::size_t n = instance->dimension;
  for (std::size_t b = 0; b < count; ++b) {
    out[b] = 0.0;
    for (std::size_t i = 0; i < n; ++i) out[b] += 0.25 * std::pow(q[b * n + i], 4);
  }
  return NONSEP_OK;
}
nonsep_status hessian_T(nonsep_instance* instance, const double*, double* out, std::size_t count) {
  const std::size_t n = instance->dimension;
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) out[b * n * n + i * n + j] = i == j ? 1.0 : 0.0;
  return NONSEP_OK;
}
nonsep_status hessian_V(nonsep_instance* instance, const double* q, double* out, std::size_t count) {
  const std::size_t n = instance->dimension;
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j)
        out[b * n * n + i * n + j] = i == j ? (BLOWUP_WRONG_HESSIAN ? 2.0 : 3.0) * q[b * n + i] * q[b * n + i] : 0.0;
  return NONSEP_OK;
}
const char* last_error(const nonsep_instance* instance) { return instance->last_error.c_str(); }

const nonsep_plugin_api api = [] {
  nonsep_plugin_api table =
      nonsep::testing::plugin_table(metadata, create, destroy, dimension, grad_T, grad_V, last_error);
  if (BLOWUP_WITH_HESSIANS) {
    table.value_T = value_T;
    table.value_V = value_V;
    table.hessian_T = hessian_T;
    table.hessian_V = hessian_V;
  }
  return table;  // no third derivatives
}();

}  // namespace

NONSEP_DEFINE_PLUGIN(api);
