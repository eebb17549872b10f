#pragma once
// The nonsep plugin SDK: write a model class (nonsep/sdk/model_adapter.hpp says what it contains), then export it
// with one line,
//
//   NONSEP_EXPORT_MODEL(Paper1D, "paper1d", "1.0.0", "one-line description", "T, V and the H it solves");
//
// which defines the symbol of plugin_abi.h (NONSEP_DEFINE_PLUGIN) and the constant function table it points at. The table's functions
// parse and range-check parameters (parameters.hpp), batch over states, compute derivatives (analytic where the
// class has them, automatic differentiation otherwise), pass non-finite results through as numbers (the host
// reports the trajectory as diverged), and turn every C++ exception into a status code with a message
// (EvaluationError -> NONSEP_EVALUATION_FAILED, InvalidParameter -> NONSEP_INVALID_PARAMETERS, anything else ->
// NONSEP_INTERNAL_ERROR). Nothing throws across the boundary.
//
// The plugin's file must be named <name>.so (nonsep_add_model() in CMake does that): the host refuses a file whose
// metadata name differs from its file name. Every SDK plugin provides all optional functions (values and
// Hessians of T and V, and integrate); its metadata adds a "derivatives" object saying, for grad_T, grad_V, hessian_T and
// hessian_V, whether it is "analytic" or "automatic".
//
// The table's optional integrate() (the fused path of plugin_abi.h) runs the core's nonsep::Integrator on
// ModelAdapter<Model> inside the plugin, so every plugin links nonsep::core (a static, position-independent
// library; nonsep_add_model() does that). The instance keeps the integrator between calls while the caller asks
// for the same one, and a workspace of states.
//
// Thread safety (as plugin_abi.h promises): metadata_json and create may be called concurrently; an instance
// holds its model, its integrator and workspace for integrate(), and its last error message, so one instance is
// for one thread at a time.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include <nlohmann/json.hpp>

#include "nonsep/core/integrator.hpp"
#include "nonsep/core/phase_space_batch.hpp"
#include "nonsep/plugin_abi.h"
#include "nonsep/sdk/dual.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "nonsep/sdk/parameters.hpp"

// The plugin-side definition of the ABI's opaque instance. Every SDK model's instance derives from it.
struct nonsep_instance {
  std::string last_error;
};

namespace nonsep::sdk {

// A model's identity, as given to NONSEP_EXPORT_MODEL.
struct ModelIdentity {
  const char* name;
  const char* version;
  const char* description;
  const char* hamiltonian;
};

// The constant function table exported for model class M. Identity is a type with a static constexpr
// ModelIdentity member `value`.
template <ModelClass M, Derivatives policy, class Identity>
class PluginTable {
  static_assert(parameter_names_are_unique<M>(), "two parameters of the model have the same name");
  static_assert(parameter_defaults_are_in_range<M>(), "a parameter's default lies outside its minimum..maximum");
  static_assert(dimension_parameter_is_bounded<M>(),
                "dimension_parameter must name an integer parameter with minimum >= 1 and maximum <= max_dimension");

  using Adapter = ModelAdapter<M, policy>;
  struct Instance : nonsep_instance {
    explicit Instance(const ParameterValues& values) : adapter(values) {}
    Adapter adapter;
    // integrate(): the integrator of the last call and what it was built from, and the states being stepped.
    std::optional<Integrator> integrator;
    nonsep_integrator integrator_built_from{};
    PhaseSpaceBatch states;
  };

  static bool same_integrator(const nonsep_integrator& a, const nonsep_integrator& b) {
    return a.scheme == b.scheme && a.form == b.form && a.order_numerator == b.order_numerator &&
           a.order_denominator == b.order_denominator && std::memcmp(&a.t2, &b.t2, sizeof(double)) == 0;
  }

  // The core's Integrator for `wanted`, built on the first call and whenever the caller asks for another one.
  // Throws InvalidArgument for an unknown scheme or form, an order the scheme lacks, or a bad t2.
  static Integrator& integrator_for(Instance& instance, const nonsep_integrator& wanted) {
    if (instance.integrator && same_integrator(instance.integrator_built_from, wanted)) return *instance.integrator;
    IntegratorSpec spec;
    switch (wanted.scheme) {
      case NONSEP_SCHEME_BASIC: spec.scheme = "basic"; break;
      case NONSEP_SCHEME_TRIPLET: spec.scheme = "triplet"; break;
      case NONSEP_SCHEME_MPE: spec.scheme = "mpe"; break;
      default: throw InvalidArgument("integrate: unknown scheme " + std::to_string(wanted.scheme) +
                                     " (expected 0 basic, 1 triplet or 2 mpe)");
    }
    switch (wanted.form) {
      case NONSEP_FORM_TTV: spec.form = HamiltonianForm::TTV; break;
      case NONSEP_FORM_VVT: spec.form = HamiltonianForm::VVT; break;
      default: throw InvalidArgument("integrate: unknown form " + std::to_string(wanted.form) +
                                     " (expected 0 TTV or 1 VVT)");
    }
    spec.order = Fraction(wanted.order_numerator, wanted.order_denominator);
    spec.t2 = wanted.t2;
    instance.integrator.reset();
    instance.integrator.emplace(spec);
    instance.integrator_built_from = wanted;
    return *instance.integrator;
  }

  static void record_error(nonsep_instance& instance, const std::string& message) noexcept {
    try {
      instance.last_error = message;
    } catch (...) {
      instance.last_error.clear();
    }
  }

  static void write_message(char* buffer, std::size_t size, const char* message) noexcept {
    if (buffer == nullptr || size == 0) return;
    const std::size_t length = std::min(std::strlen(message), size - 1);
    std::memcpy(buffer, message, length);
    buffer[length] = '\0';
  }

  // Runs `evaluate(instance)` and maps what it throws to a status, keeping the message in the instance.
  template <class Evaluate>
  static nonsep_status guarded(nonsep_instance* instance, const char* function, const Evaluate& evaluate) noexcept {
    if (instance == nullptr) return NONSEP_INTERNAL_ERROR;
    try {
      evaluate(*static_cast<Instance*>(instance));
      return NONSEP_OK;
    } catch (const EvaluationError& e) {
      record_error(*instance, e.what());
      return NONSEP_EVALUATION_FAILED;
    } catch (const std::exception& e) {
      try {
        record_error(*instance, std::string("exception in ") + function + ": " + e.what());
      } catch (...) {
      }
      return NONSEP_INTERNAL_ERROR;
    } catch (...) {
      try {
        record_error(*instance, std::string("unknown exception in ") + function);
      } catch (...) {
      }
      return NONSEP_INTERNAL_ERROR;
    }
  }

  static std::string build_metadata() {
    constexpr ModelIdentity id = Identity::value;
    nlohmann::json dimension;
    if constexpr (HasFixedDimension<M>)
      dimension = {{"fixed", M::dimension}};
    else
      dimension = {{"parameter", M::dimension_parameter}, {"max_dimension", M::max_dimension}};
    auto kind = [](bool analytic) { return analytic ? "analytic" : "automatic"; };
    const nlohmann::json metadata = {
        {"name", id.name},
        {"version", id.version},
        {"description", id.description},
        {"hamiltonian", id.hamiltonian},
        {"dimension", dimension},
        {"parameters", parameters_metadata(parameter_table<M>())},
        {"capabilities",
         {{"value_T", true}, {"value_V", true}, {"hessian_T", true}, {"hessian_V", true}, {"integrate", true}}},
        {"derivatives",
         {{"grad_T", kind(Adapter::analytic_grad_T)},
          {"grad_V", kind(Adapter::analytic_grad_V)},
          {"hessian_T", kind(Adapter::analytic_hessian_T)},
          {"hessian_V", kind(Adapter::analytic_hessian_V)}}}};
    return metadata.dump();
  }

  static const char* metadata_json() noexcept {
    try {
      static const std::string text = build_metadata();
      return text.c_str();
    } catch (...) {
      return "metadata could not be built (out of memory)";  // not JSON: the host reports it
    }
  }

  static nonsep_status create(const char* parameters_json, nonsep_instance** out, char* message,
                              std::size_t message_size) noexcept {
    if (out == nullptr) return NONSEP_INTERNAL_ERROR;
    *out = nullptr;
    try {
      const ParameterValues values =
          parse_parameters(parameter_table<M>(), parameters_json == nullptr ? "" : parameters_json);
      *out = new Instance(values);
      return NONSEP_OK;
    } catch (const InvalidParameter& e) {
      write_message(message, message_size, e.what());
      return NONSEP_INVALID_PARAMETERS;
    } catch (const std::exception& e) {
      try {
        write_message(message, message_size, (std::string("creating the model failed: ") + e.what()).c_str());
      } catch (...) {
        write_message(message, message_size, "creating the model failed");
      }
      return NONSEP_INTERNAL_ERROR;
    } catch (...) {
      write_message(message, message_size, "creating the model failed with an unknown exception");
      return NONSEP_INTERNAL_ERROR;
    }
  }

  static void destroy(nonsep_instance* instance) noexcept { delete static_cast<Instance*>(instance); }

  static std::size_t dimension(const nonsep_instance* instance) noexcept {
    return instance == nullptr ? 0 : static_cast<const Instance*>(instance)->adapter.dimension();
  }

  static const char* last_error(const nonsep_instance* instance) noexcept {
    return instance == nullptr ? "no instance" : instance->last_error.c_str();
  }

  // The batched functions: spans over the caller's arrays (sizes from the batch layout of plugin_abi.h).
#define NONSEP_SDK_BATCHED(function, per_state_of)                                                              \
  static nonsep_status function(nonsep_instance* instance, const double* x, double* out, std::size_t count) noexcept { \
    return guarded(instance, #function, [&](const Instance& self) {                                            \
      const Adapter& adapter = self.adapter;                                                                   \
      const std::size_t n = adapter.dimension();                                                               \
      adapter.function(std::span<const double>(x, count * n), std::span<double>(out, count * (per_state_of)),  \
                       count);                                                                                 \
    });                                                                                                        \
  }
  NONSEP_SDK_BATCHED(grad_T, n)
  NONSEP_SDK_BATCHED(grad_V, n)
  NONSEP_SDK_BATCHED(value_T, 1)
  NONSEP_SDK_BATCHED(value_V, 1)
  NONSEP_SDK_BATCHED(hessian_T, n * n)
  NONSEP_SDK_BATCHED(hessian_V, n * n)
#undef NONSEP_SDK_BATCHED

  // The fused path (plugin_abi.h): `steps` steps of the core's Integrator on the adapter, the first-same-as-last
  // cache and the evaluation counts handed in and out.
  static nonsep_status integrate(nonsep_instance* instance, const nonsep_integrator* wanted, double* q, double* p,
                                 double* fsal_gradient, int* fsal_valid, std::size_t count, double dt,
                                 std::uint64_t steps, std::uint64_t* grad_T_count,
                                 std::uint64_t* grad_V_count) noexcept {
    return guarded(instance, "integrate", [&](Instance& self) {
      if (wanted == nullptr || fsal_valid == nullptr || grad_T_count == nullptr || grad_V_count == nullptr ||
          (count > 0 && (q == nullptr || p == nullptr || fsal_gradient == nullptr)))
        throw InvalidArgument("integrate: a required pointer argument is null");
      Integrator& integrator = integrator_for(self, *wanted);
      if (count == 0 || steps == 0) return;
      const std::size_t n = self.adapter.dimension(), size = count * n;
      PhaseSpaceBatch& x = self.states;
      if (x.count() != count || x.dimension() != n) x = PhaseSpaceBatch(n, count);
      std::copy_n(q, size, x.q().begin());
      std::copy_n(p, size, x.p().begin());
      const std::span<double> gradient(fsal_gradient, size);
      integrator.import_cache(x, gradient, *fsal_valid != 0);
      const EvaluationCounts before = integrator.evaluations();
      for (std::uint64_t step = 0; step < steps; ++step) integrator.step(self.adapter, x, dt);
      const EvaluationCounts& after = integrator.evaluations();
      *fsal_valid = integrator.export_cache(x, gradient) ? 1 : 0;
      std::copy_n(x.q().begin(), size, q);
      std::copy_n(x.p().begin(), size, p);
      *grad_T_count += after.grad_T - before.grad_T;
      *grad_V_count += after.grad_V - before.grad_V;
    });
  }

 public:
  static constexpr nonsep_plugin_api api = {
      NONSEP_PLUGIN_ABI_VERSION,
      static_cast<std::uint32_t>(sizeof(nonsep_plugin_api)),
      &metadata_json,
      &create,
      &destroy,
      &dimension,
      &grad_T,
      &grad_V,
      &value_T,
      &value_V,
      &hessian_T,
      &hessian_V,
      &last_error,
      &integrate,
  };
};

}  // namespace nonsep::sdk

// Symbols a plugin exports (everything else stays hidden).
#define NONSEP_PLUGIN_EXPORT __attribute__((visibility("default")))

// Exports model class `Model` as this library's plugin, with analytic derivatives where the class has them.
// name, version, description and hamiltonian are string literals; name must equal the file's stem.
#define NONSEP_EXPORT_MODEL(Model, name, version, description, hamiltonian)                                    \
  NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Model, ::nonsep::sdk::Derivatives::preferred, name, version, description, \
                                       hamiltonian)

// As NONSEP_EXPORT_MODEL, choosing the derivative policy (::nonsep::sdk::Derivatives::automatic ignores the
// class's analytic derivatives; used to compare the two).
#define NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Model, policy, name, version, description, hamiltonian)       \
  namespace {                                                                                            \
  struct nonsep_exported_model_identity {                                                                \
    static constexpr ::nonsep::sdk::ModelIdentity value{name, version, description, hamiltonian};        \
  };                                                                                                     \
  }                                                                                                      \
  NONSEP_DEFINE_PLUGIN((::nonsep::sdk::PluginTable<Model, policy, nonsep_exported_model_identity>::api))
