// PluginModel: one instance of a plugin as a core model; each evaluation is one batched call of the plugin's
// table, its failure a ModelError with the plugin's message.
#include <algorithm>
#include <string>

#include "nonsep/core/base/error.hpp"
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
bool PluginModel::has_K() const { return instance_->api->grad_K != nullptr; }
bool PluginModel::has_U() const { return instance_->api->grad_U != nullptr; }
const Plugin& PluginModel::plugin() const { return instance_->plugin; }
const json& PluginModel::parameters() const { return instance_->parameters; }
bool PluginModel::has_hessian_vector_products() const { return instance_->plugin.has_hessian_vector_products(); }

namespace {

// The failures of evaluate(), out of line: a call per stage is the hot path of a single trajectory, and building
// these messages inline would make every call pay for the frame they need.
[[noreturn, gnu::cold, gnu::noinline]] void throw_bad_spans(const char* function_name, std::size_t count, std::size_t n,
                                                            std::size_t out_per_state, std::size_t in_size,
                                                            std::size_t out_size) {
  throw nonsep::InvalidArgument(std::string(function_name) + ": a batch of " + std::to_string(count) +
                                " states of dimension " + std::to_string(n) + " needs " + std::to_string(count * n) +
                                " inputs and " + std::to_string(count * out_per_state) + " outputs (found " +
                                std::to_string(in_size) + " and " + std::to_string(out_size) + ")");
}
[[noreturn, gnu::cold, gnu::noinline]] void throw_missing(const PluginModel& model, const char* function_name) {
  throw nonsep::ModelError("plugin '" + model.plugin().name() + "' does not provide " + function_name +
                           " (its capability is false)");
}
[[noreturn, gnu::cold, gnu::noinline]] void throw_failed(const PluginModel& model, nonsep_instance* handle,
                                                         const nonsep_plugin_api& api, const char* function_name,
                                                         nonsep_status status) {
  const char* message = api.last_error(handle);
  throw nonsep::ModelError("plugin '" + model.plugin().name() + "' failed in " + function_name + " (" +
                           status_name(status) + "): " + (message != nullptr && *message ? message : "no message"));
}

// Checks the spans, then makes one batched call of the table, `call(handle, in, out, count)` (absent when
// `present` is false), and turns a failure into ModelError with the plugin's message. These are the only checks
// of a call: the SDK's side trusts the sizes the ABI's batch layout gives it.
template <class Call>
void evaluate(const PluginModel& model, nonsep_instance* handle, const nonsep_plugin_api& api, bool present,
              const char* function_name, std::size_t n, std::span<const double> in, std::span<double> out,
              std::size_t count, std::size_t out_per_state, const Call& call) {
  if (in.size() < count * n || out.size() < count * out_per_state) [[unlikely]]
    throw_bad_spans(function_name, count, n, out_per_state, in.size(), out.size());
  if (!present) [[unlikely]]
    throw_missing(model, function_name);
  const nonsep_status status = call(handle, in.data(), out.data(), count);
  if (status != NONSEP_OK) [[unlikely]]
    throw_failed(model, handle, api, function_name, status);
}

}  // namespace

#define NONSEP_PLUGIN_MODEL_FUNCTION(function, out_per_state)                                                    \
  void PluginModel::function(std::span<const double> x, std::span<double> out, std::size_t count) const {        \
    const std::size_t n = instance_->dimension;                                                                  \
    const nonsep_plugin_api& api = *instance_->api;                                                              \
    evaluate(*this, instance_->handle, api, api.function != nullptr, #function, n, x, out, count, out_per_state, \
             api.function);                                                                                      \
  }
NONSEP_PLUGIN_MODEL_FUNCTION(grad_T, n)
NONSEP_PLUGIN_MODEL_FUNCTION(grad_V, n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_T, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_V, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(value_T, (static_cast<void>(n), 1))
NONSEP_PLUGIN_MODEL_FUNCTION(value_V, (static_cast<void>(n), 1))
NONSEP_PLUGIN_MODEL_FUNCTION(grad_K, n)
NONSEP_PLUGIN_MODEL_FUNCTION(grad_U, n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_K, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(hessian_U, n* n)
NONSEP_PLUGIN_MODEL_FUNCTION(value_K, (static_cast<void>(n), 1))
NONSEP_PLUGIN_MODEL_FUNCTION(value_U, (static_cast<void>(n), 1))
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
    evaluate(*this, instance_->handle, api, api.function != nullptr, #function, n, x, out, count, n,              \
             [&](nonsep_instance* handle, const double* in, double* result, std::size_t size) {                   \
               return api.function(handle, in, u.data(), result, size);                                           \
             });                                                                                                  \
  }
NONSEP_PLUGIN_MODEL_DIRECTIONAL(d3T)
NONSEP_PLUGIN_MODEL_DIRECTIONAL(d3V)
NONSEP_PLUGIN_MODEL_DIRECTIONAL(hvp_T)
NONSEP_PLUGIN_MODEL_DIRECTIONAL(hvp_V)
#undef NONSEP_PLUGIN_MODEL_DIRECTIONAL

bool PluginModel::has_hamiltonian_hessian_products() const {
  return instance_->plugin.has_hamiltonian_hessian_products();
}

void PluginModel::hvp_H(HamiltonianForm form, std::span<const double> q, std::span<const double> p,
                        std::span<const double> dq, std::span<const double> dp, std::span<double> out_q,
                        std::span<double> out_p, std::size_t count) const {
  const std::size_t n = instance_->dimension, size = count * n;
  if (p.size() < size || dq.size() < size || dp.size() < size || out_p.size() < size)
    throw_bad_spans("hvp_H", count, n, n, std::min({p.size(), dq.size(), dp.size()}), out_p.size());
  const nonsep_plugin_api& api = *instance_->api;
  evaluate(*this, instance_->handle, api, api.hvp_H != nullptr, "hvp_H", n, q, out_q, count, n,
           [&](nonsep_instance* handle, const double* in, double* result, std::size_t states) {
             const std::uint32_t abi_form = general_hamiltonian()          ? NONSEP_FORM_GENERAL
                                            : form == HamiltonianForm::TTV ? NONSEP_FORM_TTV
                                                                           : NONSEP_FORM_VVT;
             return api.hvp_H(handle, abi_form, in, p.data(), dq.data(), dp.data(), result, out_p.data(), states);
           });
}

bool PluginModel::general_hamiltonian() const { return instance_->plugin.general_hamiltonian(); }

void PluginModel::value_H(std::span<const double> q, std::span<const double> p, std::span<double> out,
                          std::size_t count) const {
  const std::size_t n = instance_->dimension;
  if (p.size() < count * n) throw_bad_spans("value_H", count, n, 1, p.size(), out.size());
  const nonsep_plugin_api& api = *instance_->api;
  evaluate(*this, instance_->handle, api, api.value_H != nullptr, "value_H", n, q, out, count, 1,
           [&](nonsep_instance* handle, const double* in, double* result, std::size_t states) {
             return api.value_H(handle, in, p.data(), result, states);
           });
}

void PluginModel::grad_H(std::span<const double> q, std::span<const double> p, std::span<double> dH_dq,
                         std::span<double> dH_dp, std::size_t count) const {
  const std::size_t n = instance_->dimension, size = count * n;
  if (p.size() < size || dH_dp.size() < size) throw_bad_spans("grad_H", count, n, n, p.size(), dH_dp.size());
  const nonsep_plugin_api& api = *instance_->api;
  evaluate(*this, instance_->handle, api, api.grad_H != nullptr, "grad_H", n, q, dH_dq, count, n,
           [&](nonsep_instance* handle, const double* in, double* result, std::size_t states) {
             return api.grad_H(handle, in, p.data(), result, dH_dp.data(), states);
           });
}

bool PluginModel::has_product_energy(HamiltonianForm form) const {
  return product_energy_ && instance_->plugin.has_product_energy(form);
}

void PluginModel::product_energy(HamiltonianForm form, std::span<const double> q, std::span<const double> p,
                                 std::span<double> out, std::size_t count) const {
  const std::size_t n = instance_->dimension;
  const bool ttv = form == HamiltonianForm::TTV;
  const char* name = ttv ? "energy_TTV" : "energy_VVT";
  if (p.size() < count * n) throw_bad_spans(name, count, n, 1, p.size(), out.size());
  const nonsep_plugin_api& api = *instance_->api;
  const auto entry = ttv ? api.energy_TTV : api.energy_VVT;
  evaluate(*this, instance_->handle, api, entry != nullptr, name, n, q, out, count, 1,
           [&](nonsep_instance* handle, const double* in, double* result, std::size_t size) {
             return entry(handle, in, p.data(), result, size);
           });
}

PluginModel PluginModel::without_product_energy() const {
  PluginModel model = *this;
  model.product_energy_ = false;
  return model;
}

PluginModel PluginModel::with_kernel() const {
  const auto chosen = plugin().kernels().chosen;
  return with_kernel(chosen ? *chosen : plugin().kernels().usable.size());
}

PluginModel PluginModel::with_kernel(std::size_t instruction_set) const {
  PluginModel model = *this;
  const auto& usable = plugin().kernels().usable;
  model.kernel_.reset();
  if (instruction_set < usable.size() && usable[instruction_set])
    model.kernel_ = static_cast<std::uint32_t>(instruction_set);
  model.gauss_kernel_ = instance_->api->gauss_steps != nullptr && instruction_set_pin() != "evaluation";
  return model;
}

std::uint64_t PluginModel::kernel_calls() const { return instance_->kernel_calls; }

namespace {

// A call's arguments across the boundary, its sizes checked for states of dimension n.
nonsep_chin_steps_args steps_args(const ChinStepsCall& call, std::uint32_t instruction_set, std::size_t n,
                                  const char* function) {
  const std::size_t size = call.count * n;
  if (call.q.size() != size || call.p.size() != size || call.outer_gradient.size() != size ||
      call.inner_gradient.size() != size ||
      !chin_eps_fit(call.eps.size(), call.substeps, call.count, call.weights.size())) [[unlikely]]
    throw_bad_spans(function, call.count, n, n, call.q.size(), call.p.size());
  return nonsep_chin_steps_args{call.form == HamiltonianForm::TTV ? NONSEP_FORM_TTV : NONSEP_FORM_VVT,
                                instruction_set,
                                call.coefficients.t1,
                                call.coefficients.t2,
                                call.coefficients.v0,
                                call.coefficients.v1,
                                call.coefficients.v2,
                                call.eps.data(),
                                call.eps.size(),
                                call.substeps,
                                call.steps,
                                call.count,
                                call.q.data(),
                                call.p.data(),
                                call.outer_gradient.data(),
                                call.inner_gradient.data(),
                                call.weights.empty() ? nullptr : call.weights.data(),
                                call.weights.size()};
}

}  // namespace

bool PluginModel::chin_steps(const ChinStepsCall& call) const {
  if (!kernel_) return false;
  const nonsep_plugin_api& api = *instance_->api;
  const nonsep_chin_steps_args args = steps_args(call, *kernel_, instance_->dimension, "chin_steps");
  const nonsep_status status = api.chin_steps(instance_->handle, &args);
  if (status != NONSEP_OK) [[unlikely]]
    throw_failed(*this, instance_->handle, api, "chin_steps", status);
  ++instance_->kernel_calls;
  return true;
}

bool PluginModel::chin_tangent_steps(const ChinTangentStepsCall& call) const {
  const nonsep_plugin_api& api = *instance_->api;
  if (!kernel_ || api.chin_tangent_steps == nullptr) return false;
  const std::size_t n = instance_->dimension, size = call.steps.count * call.vectors * n;
  if (!call.steps.weights.empty() || call.vectors == 0 || call.tangent_q.size() != size ||
      call.tangent_p.size() != size) [[unlikely]]
    throw_bad_spans("chin_tangent_steps", call.steps.count * call.vectors, n, n, call.tangent_q.size(),
                    call.tangent_p.size());
  const nonsep_chin_tangent_steps_args args{steps_args(call.steps, *kernel_, n, "chin_tangent_steps"), call.vectors,
                                            call.tangent_q.data(), call.tangent_p.data()};
  const nonsep_status status = api.chin_tangent_steps(instance_->handle, &args);
  if (status != NONSEP_OK) [[unlikely]]
    throw_failed(*this, instance_->handle, api, "chin_tangent_steps", status);
  ++instance_->kernel_calls;
  return true;
}

}  // namespace nonsep::host

namespace nonsep::host {

bool PluginModel::gauss_steps(const GaussStepsCall& call) const {
  if (!gauss_kernel_) return false;
  const std::size_t n = instance_->dimension, s = call.stages, size = call.count * n, stages = s * size,
                    rows = call.count * gauss_memory_width(n, s);
  if (s < 1 || s > gauss_max_stages || call.max_iterations < 1 || call.mu.size() != s * s || call.hb.size() != s ||
      (!call.nu.empty() && call.nu.size() != s * s) || call.q.size() != size || call.p.size() != size ||
      call.memory.size() != rows || call.next_memory.size() != rows || call.points_q.size() != stages ||
      call.points_p.size() != stages || call.iterations.size() != call.count || call.outcome.size() != call.count)
      [[unlikely]]
    throw_bad_spans("gauss_steps", call.count, n, n, call.q.size(), call.p.size());
  static_assert(sizeof(int) == sizeof(std::int32_t) && sizeof(GaussOutcome) == sizeof(std::uint8_t));
  const std::uint32_t form = general_hamiltonian()               ? NONSEP_FORM_GENERAL
                             : call.form == HamiltonianForm::TTV ? NONSEP_FORM_TTV
                                                                 : NONSEP_FORM_VVT;
  const nonsep_gauss_steps_args args{form,
                                     static_cast<std::uint32_t>(s),
                                     static_cast<std::uint32_t>(call.max_iterations),
                                     call.dt,
                                     call.mu.data(),
                                     call.hb.data(),
                                     call.nu.empty() ? nullptr : call.nu.data(),
                                     call.count,
                                     call.q.data(),
                                     call.p.data(),
                                     call.memory.data(),
                                     call.next_memory.data(),
                                     call.points_q.data(),
                                     call.points_p.data(),
                                     reinterpret_cast<std::int32_t*>(call.iterations.data()),
                                     reinterpret_cast<std::uint8_t*>(call.outcome.data())};
  if (instance_->api->gauss_steps(instance_->handle, &args) != NONSEP_OK) return false;
  ++instance_->kernel_calls;
  return true;
}

}  // namespace nonsep::host
