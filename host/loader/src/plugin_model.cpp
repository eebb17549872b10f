// PluginModel: one instance of a plugin as a core model; each evaluation is one batched call of the plugin's
// table, its failure a ModelError with the plugin's message.
#include <string>

#include "nonsep/core/error.hpp"
#include "plugin_internals.hpp"

namespace nonsep::host {

using nlohmann::json;

const char* status_name(nonsep_status status) {
  switch (status) {
    case NONSEP_OK:
      return "ok";
    case NONSEP_INVALID_PARAMETERS:
      return "invalid parameters";
    case NONSEP_EVALUATION_FAILED:
      return "evaluation failed";
    case NONSEP_INTERNAL_ERROR:
      return "internal error";
    case NONSEP_UNSUPPORTED:
      return "unsupported";
  }
  return "unknown status";
}

std::size_t PluginModel::dimension() const { return instance_->dimension; }
const Plugin& PluginModel::plugin() const { return instance_->plugin; }
const json& PluginModel::parameters() const { return instance_->parameters; }

namespace {

// Checks the spans, then makes one batched call of the table, `call(handle, in, out, count)` (absent when
// `present` is false), and turns a failure into ModelError with the plugin's message.
template <class Call>
void evaluate(const PluginModel& model, nonsep_instance* handle, const nonsep_plugin_api& api, bool present,
              const char* function_name, std::span<const double> in, std::span<double> out, std::size_t count,
              std::size_t out_per_state, const Call& call) {
  const std::size_t n = model.dimension();
  if (in.size() < count * n || out.size() < count * out_per_state)
    throw nonsep::InvalidArgument(std::string(function_name) + ": a batch of " + std::to_string(count) +
                                  " states of dimension " + std::to_string(n) + " needs " + std::to_string(count * n) +
                                  " inputs and " + std::to_string(count * out_per_state) + " outputs (found " +
                                  std::to_string(in.size()) + " and " + std::to_string(out.size()) + ")");
  if (!present)
    throw nonsep::ModelError("plugin '" + model.plugin().name() + "' does not provide " + function_name +
                             " (its capability is false)");
  const nonsep_status status = call(handle, in.data(), out.data(), count);
  if (status != NONSEP_OK) {
    const char* message = api.last_error(handle);
    throw nonsep::ModelError("plugin '" + model.plugin().name() + "' failed in " + function_name + " (" +
                             status_name(status) + "): " + (message != nullptr && *message ? message : "no message"));
  }
}

}  // namespace

#define NONSEP_PLUGIN_MODEL_FUNCTION(function, out_per_state)                                                 \
  void PluginModel::function(std::span<const double> x, std::span<double> out, std::size_t count) const {     \
    const std::size_t n = instance_->dimension;                                                               \
    const nonsep_plugin_api& api = *instance_->api;                                                           \
    evaluate(*this, instance_->handle, api, api.function != nullptr, #function, x, out, count, out_per_state, \
             api.function);                                                                                   \
  }
NONSEP_PLUGIN_MODEL_FUNCTION(grad_T, n)
NONSEP_PLUGIN_MODEL_FUNCTION(grad_V, n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_T, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_V, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(value_T, (static_cast<void>(n), 1))
NONSEP_PLUGIN_MODEL_FUNCTION(value_V, (static_cast<void>(n), 1))
#undef NONSEP_PLUGIN_MODEL_FUNCTION

#define NONSEP_PLUGIN_MODEL_DIRECTIONAL(function)                                                                 \
  void PluginModel::function(std::span<const double> x, std::span<const double> u, std::span<double> out,         \
                             std::size_t count) const {                                                           \
    const std::size_t n = instance_->dimension;                                                                   \
    if (u.size() < count * n)                                                                                     \
      throw nonsep::InvalidArgument(#function ": a batch of " + std::to_string(count) + " states of dimension " + \
                                    std::to_string(n) + " needs " + std::to_string(count * n) +                   \
                                    " direction components (found " + std::to_string(u.size()) + ")");            \
    const nonsep_plugin_api& api = *instance_->api;                                                               \
    evaluate(*this, instance_->handle, api, api.function != nullptr, #function, x, out, count, n,                 \
             [&](nonsep_instance* handle, const double* in, double* result, std::size_t size) {                   \
               return api.function(handle, in, u.data(), result, size);                                           \
             });                                                                                                  \
  }
NONSEP_PLUGIN_MODEL_DIRECTIONAL(d3T)
NONSEP_PLUGIN_MODEL_DIRECTIONAL(d3V)
#undef NONSEP_PLUGIN_MODEL_DIRECTIONAL

}  // namespace nonsep::host
