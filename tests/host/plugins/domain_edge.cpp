// A test plugin for `nonsep inspect --check` on models with a domain, written against the C ABI (the SDK refuses
// non-finite results): V is defined only for q_i > edge, and every V function returns NaN outside, as a model
// with log or sqrt would.
//
//   T(p) = |p|^2 / 2              grad T = p,                    Hess T = I
//   V(q) = sum_i log(q_i - edge)  grad V = 1 / (q_i - edge),     Hess V = diag(-1 / (q_i - edge)^2)   (q_i > edge)
//
// Parameters: edge (number, default 0); dimension (integer, 0 to 10^9: 0 gives a model with nothing to check,
// large values a check that cannot fit in memory).
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "nonsep/plugin_abi.h"
#include "support/plugin_table.hpp"

struct nonsep_instance {
  std::size_t dimension = 1;
  double edge = 0.0;
};

namespace {

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();

const char* metadata() {
  static const std::string text =
      nlohmann::json{
          {"name", "domain_edge"},
          {"version", "0.0.1"},
          {"description", "host test model: V = sum log(q_i - edge), NaN for q_i <= edge"},
          {"hamiltonian", "T = |p|^2/2, V = sum log(q_i - edge)"},
          {"dimension", {{"parameter", "dimension"}}},
          {"parameters",
           {{{"name", "dimension"},
             {"type", "integer"},
             {"default", 1},
             {"minimum", 0},
             {"maximum", 1000000000},
             {"description", "number of degrees of freedom"}},
            {{"name", "edge"}, {"type", "number"}, {"default", 0.0}, {"description", "V is defined for q_i > edge"}}}},
          {"thread_safe", true},
          {"capabilities", {{"value_T", true}, {"value_V", true}, {"hessian_T", true}, {"hessian_V", true}}}}
          .dump();
  return text.c_str();
}

nonsep_status create(const char* parameters_json, nonsep_instance** out, char* message, std::size_t size) {
  *out = nullptr;
  try {
    const auto parameters = nlohmann::json::parse(parameters_json);
    auto instance = new nonsep_instance;
    instance->dimension = parameters.value("dimension", std::size_t{1});
    instance->edge = parameters.value("edge", 0.0);
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
  for (std::size_t i = 0; i < count * instance->dimension; ++i)
    out[i] = q[i] > instance->edge ? 1.0 / (q[i] - instance->edge) : not_a_number;
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
    for (std::size_t i = 0; i < n; ++i)
      out[b] += q[b * n + i] > instance->edge ? std::log(q[b * n + i] - instance->edge) : not_a_number;
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
    for (std::size_t i = 0; i < n; ++i) {
      const double d = q[b * n + i] - instance->edge;
      for (std::size_t j = 0; j < n; ++j)
        out[b * n * n + i * n + j] = i != j ? 0.0 : d > 0 ? -1.0 / (d * d) : not_a_number;
    }
  return NONSEP_OK;
}
const char* last_error(const nonsep_instance*) { return ""; }

const nonsep_plugin_api api = [] {
  nonsep_plugin_api table =
      nonsep::testing::plugin_table(metadata, create, destroy, dimension, grad_T, grad_V, last_error);
  table.value_T = value_T;
  table.value_V = value_V;
  table.hessian_T = hessian_T;
  table.hessian_V = hessian_V;
  return table;  // no third derivatives
}();

}  // namespace

NONSEP_DEFINE_PLUGIN(api);
