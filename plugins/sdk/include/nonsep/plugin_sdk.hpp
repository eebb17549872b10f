#pragma once
// The nonsep plugin SDK: write a model class (nonsep/sdk/model_adapter.hpp says what it contains), then export it
// with one line,
//
//   NONSEP_EXPORT_MODEL(Paper1D, "paper1d", "1.0.0", "one-line description", "T, V and the H it solves");
//
// which defines the symbol of plugin_abi.h (NONSEP_DEFINE_PLUGIN) and the constant function table it points at.
// The table's functions parse and range-check parameters (parameters.hpp), batch over states, compute derivatives
// (analytic where the class has them, automatic differentiation otherwise), pass non-finite results through as
// numbers (the host reports the trajectory as diverged), and turn every C++ exception into a status code with a
// message (EvaluationError -> NONSEP_EVALUATION_FAILED, InvalidParameter -> NONSEP_INVALID_PARAMETERS, anything
// else -> NONSEP_INTERNAL_ERROR). Nothing throws across the boundary.
//
// The plugin's file must be named <name>.so (nonsep_add_model() in CMake does that): the host refuses a file whose
// metadata name differs from its file name. Every SDK plugin provides all optional functions of plugin_abi.h
// for T and V (values, Hessians, directional third derivatives, Hessian-vector products) and the stepping kernels
// chin_steps and chin_tangent_steps: the core's chin_kernel_steps and chin_tangent_kernel_blocks with the model
// inlined, compiled for the instruction sets of
// kernels.hpp (metadata "kernels": {"instruction_sets"}); no stepping code is written here; and, where the model's
// T and V (or gradient templates) compile for one more level of dual numbers, or where it writes out their mixed third
// and fourth derivatives, the directional derivative of grad H, hvp_H (model_adapter.hpp; capability "hvp_H"). Its
// metadata adds a "derivatives" object saying, for grad_T, grad_V, hessian_T, hessian_V, d3T, d3V, hvp_T, hvp_V and
// hvp_H (where present), whether it is "analytic" (written by the model; for hvp_H, from the written-out mixed third
// and fourth derivatives of both T and V) or "automatic" (of the gradient templates where the model has them, else of
// T and V). A model that writes out energy_TTV or energy_VVT (the product term of H) fills that
// entry; the other stays null.
// A model class with K(p) or U(q) (model_adapter.hpp) also fills grad_K, value_K, hessian_K (resp. the U ones) of
// ABI version 4, announces them as capabilities and adds them to "derivatives"; the absent part's entries are null.
//
// A model class given by H(q, p) itself (nonsep/sdk/hamiltonian_adapter.hpp) is exported with
//
//   NONSEP_EXPORT_HAMILTONIAN(HenonHeiles, "henon_heiles", "1.0.0", "one-line description", "what H is");
//
// whose table (plugin_abi.h version 6, "hamiltonian_form": "general") has value_H, grad_H and hvp_H (form
// NONSEP_FORM_GENERAL), by automatic differentiation of H over (q, p) where the class does not write them, and none
// of the entries of T, V, K, U or the kernels.
//
// Thread safety (as plugin_abi.h promises): metadata_json and create may be called concurrently; an instance
// holds its model and its last error message, so one instance is for one thread at a time. The metadata says
// "thread_safe": true: distinct instances share nothing mutable, provided the model class keeps no mutable
// global or static state (a model that does is not for this SDK's export macro; see plugin_abi.h).
//
// The SDK is these headers and one small static library, nonsep::sdk in CMake (plugins/sdk/src): what reads and writes
// JSON (parse_parameters, metadata_text), compiled once instead of in every plugin (parameters.hpp says why). A
// plugin links nothing else of nonsep (it includes a few header-only core headers, nonsep/core/base/error.hpp).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <span>
#include <stdexcept>
#include <string>

#include "nonsep/core/kernel/gauss_stages.hpp"
#include "nonsep/plugin_abi.h"
#include "nonsep/sdk/dual.hpp"
#include "nonsep/sdk/hamiltonian_adapter.hpp"
#include "nonsep/sdk/kernels.hpp"
#include "nonsep/sdk/metadata.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "nonsep/sdk/parameters.hpp"

// The plugin-side definition of the ABI's opaque instance. Every SDK model's instance derives from it.
struct nonsep_instance {
  std::string last_error;
};

namespace nonsep::sdk {

// What every table of the SDK shares, for an adapter type (ModelAdapter, HamiltonianAdapter) of a model class M: the
// instance holding the adapter and its last error, the mapping of exceptions to statuses, create, destroy,
// dimension, last_error, and the metadata's identity, dimension and parameters.
template <class Adapter>
class PluginTableBase {
 protected:
  using M = typename Adapter::Model;
  static_assert(parameter_names_are_unique<M>(), "two parameters of the model have the same name");
  static_assert(parameter_defaults_are_in_range<M>(), "a parameter's default lies outside its minimum..maximum");
  static_assert(dimension_parameter_is_bounded<M>(),
                "dimension_parameter must name an integer parameter with minimum >= 1 and maximum <= max_dimension");

  struct Instance : nonsep_instance {
    explicit Instance(const ParameterValues& values) : adapter(values) {}
    Adapter adapter;
  };

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

  // The metadata's identity, dimension and parameters (metadata.hpp).
  static PluginFacts common_facts(const ModelIdentity& id) {
    PluginFacts facts;
    facts.identity = id;
    if constexpr (HasFixedDimension<M>) {
      facts.fixed_dimension = M::dimension;
    } else {
      facts.dimension_parameter = M::dimension_parameter;
      facts.max_dimension = M::max_dimension;
    }
    facts.parameters = parameter_table<M>();
    return facts;
  }
  template <std::string (*build)()>
  static const char* cached_metadata() noexcept {
    try {
      static const std::string text = build();
      return text.c_str();
    } catch (...) {
      return "metadata could not be built (out of memory)";  // not JSON: the host reports it
    }
  }
  // (the rest of the base below: create, destroy, dimension, last_error)
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

  // The Gauss-Legendre stepping kernel (plugin_abi.h gauss_steps): the core's gauss_kernel_steps with this model
  // inlined (kernels.hpp, GaussKernels); its arguments checked (std::invalid_argument names what is wrong).
  static nonsep_status gauss_steps(nonsep_instance* instance, const nonsep_gauss_steps_args* args) noexcept {
    return guarded(instance, "gauss_steps", [&](const Instance& self) {
      if (args == nullptr) throw std::invalid_argument("gauss_steps: no arguments");
      constexpr bool general = !ModelWithThirdDerivatives<Adapter>;
      const bool form_fits =
          general ? args->form == NONSEP_FORM_GENERAL : args->form == NONSEP_FORM_TTV || args->form == NONSEP_FORM_VVT;
      if (!form_fits) throw std::invalid_argument("gauss_steps: form " + std::to_string(args->form) + " of this model");
      if (args->stages < 1 || args->stages > gauss_max_stages || args->max_iterations < 1)
        throw std::invalid_argument("gauss_steps: " + std::to_string(args->stages) + " stages and " +
                                    std::to_string(args->max_iterations) +
                                    " iterations (expected 1 to 8 stages, at least one iteration)");
      const std::size_t s = args->stages, n = self.adapter.dimension(), size = args->count * n, stages = s * size,
                        rows = args->count * gauss_memory_width(n, s);
      const auto in = [](const double* x, std::size_t length) { return std::span<const double>(x, length); };
      const auto out = [](double* x, std::size_t length) { return std::span<double>(x, length); };
      static_assert(sizeof(int) == sizeof(std::int32_t) && sizeof(GaussOutcome) == sizeof(std::uint8_t));
      const GaussStepsCall call{args->form == NONSEP_FORM_VVT ? HamiltonianForm::VVT : HamiltonianForm::TTV,
                                s,
                                static_cast<int>(args->max_iterations),
                                args->dt,
                                in(args->mu, s * s),
                                in(args->hb, s),
                                args->nu == nullptr ? std::span<const double>() : in(args->nu, s * s),
                                args->count,
                                out(args->q, size),
                                out(args->p, size),
                                in(args->memory, rows),
                                out(args->next_memory, rows),
                                out(args->points_q, stages),
                                out(args->points_p, stages),
                                std::span<int>(reinterpret_cast<int*>(args->iterations), args->count),
                                std::span<GaussOutcome>(reinterpret_cast<GaussOutcome*>(args->outcome), args->count)};
      GaussKernels<Adapter>::run(self.adapter, call);
    });
  }
};

// The constant function table exported for model class M. Identity is a type with a static constexpr
// ModelIdentity member `value`.
template <ModelClass M, Derivatives policy, class Identity>
class PluginTable : PluginTableBase<ModelAdapter<M, policy>> {
  using Adapter = ModelAdapter<M, policy>;
  using Base = PluginTableBase<Adapter>;
  using Base::create;
  using Base::destroy;
  using Base::dimension;
  using Base::guarded;
  using Base::last_error;
  using Base::record_error;
  using typename Base::Instance;

  static std::string build_metadata() {
    auto kind = [](bool analytic) { return analytic ? "analytic" : "automatic"; };
    PluginFacts facts = Base::common_facts(Identity::value);
    facts.capabilities = {{"value_T", true},
                          {"value_V", true},
                          {"hessian_T", true},
                          {"hessian_V", true},
                          {"d3T", true},
                          {"d3V", true},
                          {"hvp_T", true},
                          {"hvp_V", true},
                          {"chin_steps", true},
                          {"energy_TTV", Adapter::analytic_energy_TTV},
                          {"energy_VVT", Adapter::analytic_energy_VVT},
                          {"hvp_H", Adapter::has_hamiltonian_hessian},
                          {"chin_tangent_steps", NONSEP_SDK_TANGENT_KERNELS != 0},
                          {"gauss_steps", true}};
    for (const char* function : {"grad_K", "value_K", "hessian_K"}) facts.capabilities.emplace_back(function, HasK<M>);
    for (const char* function : {"grad_U", "value_U", "hessian_U"}) facts.capabilities.emplace_back(function, HasU<M>);
    facts.derivatives = {{"grad_T", kind(Adapter::analytic_grad_T)},
                         {"grad_V", kind(Adapter::analytic_grad_V)},
                         {"hessian_T", kind(Adapter::analytic_hessian_T)},
                         {"hessian_V", kind(Adapter::analytic_hessian_V)},
                         {"d3T", kind(Adapter::analytic_d3T)},
                         {"d3V", kind(Adapter::analytic_d3V)},
                         {"hvp_T", kind(Adapter::analytic_hvp_T)},
                         {"hvp_V", kind(Adapter::analytic_hvp_V)}};
    if constexpr (Adapter::has_hamiltonian_hessian)  // from written-out mixed third and fourth derivatives, or duals
      facts.derivatives.emplace_back("hvp_H", kind(Adapter::analytic_mixed_T && Adapter::analytic_mixed_V));
    if constexpr (HasK<M>) {
      facts.derivatives.emplace_back("grad_K", kind(Adapter::analytic_grad_K));
      facts.derivatives.emplace_back("hessian_K", kind(Adapter::analytic_hessian_K));
    }
    if constexpr (HasU<M>) {
      facts.derivatives.emplace_back("grad_U", kind(Adapter::analytic_grad_U));
      facts.derivatives.emplace_back("hessian_U", kind(Adapter::analytic_hessian_U));
    }
    facts.automatic_differentiation = automatic_differentiation_text<Adapter>();
    facts.has_kernels = true;
    facts.instruction_sets = kernel_instruction_sets;
    return metadata_text(facts);
  }

  static const char* metadata_json() noexcept { return Base::template cached_metadata<&build_metadata>(); }

  // The batched functions: spans over the caller's arrays (sizes from the batch layout of plugin_abi.h).
#define NONSEP_SDK_BATCHED(function, per_state_of)                                                                     \
  static nonsep_status function(nonsep_instance* instance, const double* x, double* out, std::size_t count) noexcept { \
    return guarded(instance, #function, [&](const Instance& self) {                                                    \
      const Adapter& adapter = self.adapter;                                                                           \
      const std::size_t n = adapter.dimension();                                                                       \
      adapter.function(std::span<const double>(x, count * n), std::span<double>(out, count * (per_state_of)), count);  \
    });                                                                                                                \
  }
  NONSEP_SDK_BATCHED(grad_T, n)
  NONSEP_SDK_BATCHED(grad_V, n)
  NONSEP_SDK_BATCHED(value_T, 1)
  NONSEP_SDK_BATCHED(value_V, 1)
  NONSEP_SDK_BATCHED(hessian_T, n* n)
  NONSEP_SDK_BATCHED(hessian_V, n* n)
#undef NONSEP_SDK_BATCHED

  // The separable part's functions: compiled for every model, in the table only for a model with that part (the
  // body of the absent one is never reached; it answers NONSEP_UNSUPPORTED).
#define NONSEP_SDK_SEPARABLE(function, present, per_state_of)                                                          \
  static nonsep_status function(nonsep_instance* instance, const double* x, double* out, std::size_t count) noexcept { \
    if constexpr (present) {                                                                                           \
      return guarded(instance, #function, [&](const Instance& self) {                                                  \
        const Adapter& adapter = self.adapter;                                                                         \
        const std::size_t n = adapter.dimension();                                                                     \
        adapter.function(std::span<const double>(x, count * n), std::span<double>(out, count * (per_state_of)),        \
                         count);                                                                                       \
      });                                                                                                              \
    } else {                                                                                                           \
      static_cast<void>(instance), static_cast<void>(x), static_cast<void>(out), static_cast<void>(count);             \
      return NONSEP_UNSUPPORTED;                                                                                       \
    }                                                                                                                  \
  }
  NONSEP_SDK_SEPARABLE(grad_K, HasK<M>, n)
  NONSEP_SDK_SEPARABLE(grad_U, HasU<M>, n)
  NONSEP_SDK_SEPARABLE(value_K, HasK<M>, 1)
  NONSEP_SDK_SEPARABLE(value_U, HasU<M>, 1)
  NONSEP_SDK_SEPARABLE(hessian_K, HasK<M>, n* n)
  NONSEP_SDK_SEPARABLE(hessian_U, HasU<M>, n* n)
#undef NONSEP_SDK_SEPARABLE

  // The directional third derivatives: x, u and out each hold count*n numbers.
  // The directional third derivatives and the Hessian-vector products: x, u and out each hold count*n numbers.
#define NONSEP_SDK_DIRECTIONAL(function)                                                                  \
  static nonsep_status function(nonsep_instance* instance, const double* x, const double* u, double* out, \
                                std::size_t count) noexcept {                                             \
    return guarded(instance, #function, [&](const Instance& self) {                                       \
      const Adapter& adapter = self.adapter;                                                              \
      const std::size_t size = count * adapter.dimension();                                               \
      adapter.function(std::span<const double>(x, size), std::span<const double>(u, size),                \
                       std::span<double>(out, size), count);                                              \
    });                                                                                                   \
  }
  NONSEP_SDK_DIRECTIONAL(d3T)
  NONSEP_SDK_DIRECTIONAL(d3V)
  NONSEP_SDK_DIRECTIONAL(hvp_T)
  NONSEP_SDK_DIRECTIONAL(hvp_V)
#undef NONSEP_SDK_DIRECTIONAL

  // The product term of H written out by the model (plugin_abi.h energy_TTV, energy_VVT): q and p hold count*n
  // numbers, out count.
  template <HamiltonianForm form>
  static nonsep_status product_energy(nonsep_instance* instance, const double* q, const double* p, double* out,
                                      std::size_t count) noexcept {
    return guarded(instance, form == HamiltonianForm::TTV ? "energy_TTV" : "energy_VVT", [&](const Instance& self) {
      const Adapter& adapter = self.adapter;
      const std::size_t size = count * adapter.dimension();
      if constexpr (Adapter::analytic_energy_TTV || Adapter::analytic_energy_VVT)
        adapter.product_energy(form, std::span<const double>(q, size), std::span<const double>(p, size),
                               std::span<double>(out, count), count);
      else
        static_cast<void>(size), static_cast<void>(out);
    });
  }

  // The directional derivative of grad H (plugin_abi.h hvp_H): q, p, dq, dp, out_q and out_p each hold count*n
  // numbers. A form other than TTV and VVT is NONSEP_UNSUPPORTED.
  static nonsep_status hvp_H(nonsep_instance* instance, std::uint32_t form, const double* q, const double* p,
                             const double* dq, const double* dp, double* out_q, double* out_p,
                             std::size_t count) noexcept {
    if (instance != nullptr && form != NONSEP_FORM_TTV && form != NONSEP_FORM_VVT) {
      record_error(*instance, "hvp_H: form " + std::to_string(form) + " is neither TTV (0) nor VVT (1)");
      return NONSEP_UNSUPPORTED;
    }
    return guarded(instance, "hvp_H", [&](const Instance& self) {
      if constexpr (Adapter::has_hamiltonian_hessian) {
        const Adapter& adapter = self.adapter;
        const std::size_t size = count * adapter.dimension();
        adapter.hvp_H(form == NONSEP_FORM_VVT ? HamiltonianForm::VVT : HamiltonianForm::TTV,
                      std::span<const double>(q, size), std::span<const double>(p, size),
                      std::span<const double>(dq, size), std::span<const double>(dp, size),
                      std::span<double>(out_q, size), std::span<double>(out_p, size), count);
      } else {
        static_cast<void>(self), static_cast<void>(q), static_cast<void>(p), static_cast<void>(dq);
        static_cast<void>(dp), static_cast<void>(out_q), static_cast<void>(out_p);
      }
    });
  }

  // The stepping kernel (plugin_abi.h chin_steps): the core's chin_kernel_steps with this model inlined, for the
  // instruction set the host asks for (kernels.hpp).
  // The arguments of chin_steps as the core's call, checked (std::invalid_argument names what is wrong).
  static ChinStepsCall steps_call(const Adapter& adapter, const nonsep_chin_steps_args* args, const char* function) {
    const std::string name(function);
    if (args == nullptr) throw std::invalid_argument(name + ": no arguments");
    const std::size_t size = args->count * adapter.dimension();
    if (args->form != NONSEP_FORM_TTV && args->form != NONSEP_FORM_VVT)
      throw std::invalid_argument(name + ": form " + std::to_string(args->form) + " is neither TTV (0) nor VVT (1)");
    if (args->terms != 0 && (args->terms < 2 || args->weights == nullptr))
      throw std::invalid_argument(name + ": an expansion of " + std::to_string(args->terms) + " terms" +
                                  (args->weights == nullptr ? " without weights" : "") +
                                  " (expected 0 for basic steps, or at least 2 terms with their weights)");
    if (!chin_eps_fit(args->eps_count, args->substeps, args->count, args->terms))
      throw std::invalid_argument(
          name + ": " + std::to_string(args->eps_count) + " step sizes for " + std::to_string(args->substeps) +
          " sub-steps of " + std::to_string(args->count) + " states and " + std::to_string(args->terms) +
          " expansion terms (expected one per term with terms, else one per sub-step, or with one sub-step 1 or "
          "one per state)");
    return ChinStepsCall{args->form == NONSEP_FORM_VVT ? HamiltonianForm::VVT : HamiltonianForm::TTV,
                         ChinCoefficients{args->t1, args->t2, args->v0, args->v1, args->v2},
                         std::span<const double>(args->eps, args->eps_count),
                         args->substeps,
                         args->steps,
                         args->count,
                         std::span<double>(args->q, size),
                         std::span<double>(args->p, size),
                         std::span<double>(args->outer_gradient, size),
                         std::span<double>(args->inner_gradient, size),
                         std::span<const double>(args->weights, args->terms)};
  }
  [[noreturn]] static void throw_unknown_instruction_set(const char* function, std::uint32_t instruction_set) {
    throw std::invalid_argument(std::string(function) + ": instruction set " + std::to_string(instruction_set) +
                                " is not among this plugin's kernels (its metadata lists them)");
  }

  // The stepping kernel (plugin_abi.h chin_steps): the core's chin_kernel_steps with this model inlined, for the
  // instruction set the host asks for (kernels.hpp).
  static nonsep_status chin_steps(nonsep_instance* instance, const nonsep_chin_steps_args* args) noexcept {
    return guarded(instance, "chin_steps", [&](const Instance& self) {
      const ChinStepsCall call = steps_call(self.adapter, args, "chin_steps");
      if (!ChinKernels<Adapter>::run(args->instruction_set, self.adapter, call))
        throw_unknown_instruction_set("chin_steps", args->instruction_set);
    });
  }

  // The tangent kernel (plugin_abi.h chin_tangent_steps): the core's chin_tangent_kernel_blocks with this model
  // inlined, for the instruction set the host asks for.
  static nonsep_status chin_tangent_steps(nonsep_instance* instance,
                                          const nonsep_chin_tangent_steps_args* args) noexcept {
    return guarded(instance, "chin_tangent_steps", [&](const Instance& self) {
      if (args == nullptr) throw std::invalid_argument("chin_tangent_steps: no arguments");
      const ChinStepsCall steps = steps_call(self.adapter, &args->steps, "chin_tangent_steps");
      const std::size_t n = self.adapter.dimension(), k = args->vectors;
      if (args->steps.terms != 0) throw std::invalid_argument("chin_tangent_steps: an expansion (terms must be 0)");
      if (k < 1 || k > 2 * n)
        throw std::invalid_argument("chin_tangent_steps: " + std::to_string(k) + " vectors per state (expected 1 to " +
                                    std::to_string(2 * n) + ")");
      const std::size_t size = args->steps.count * k * n;
      const ChinTangentStepsCall call{steps, k, std::span<double>(args->tangent_q, size),
                                      std::span<double>(args->tangent_p, size)};
      if (!ChinKernels<Adapter>::run_tangent(args->steps.instruction_set, self.adapter, call))
        throw_unknown_instruction_set("chin_tangent_steps", args->steps.instruction_set);
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
      &d3T,
      &d3V,
      HasK<M> ? &grad_K : nullptr,
      HasU<M> ? &grad_U : nullptr,
      HasK<M> ? &value_K : nullptr,
      HasU<M> ? &value_U : nullptr,
      HasK<M> ? &hessian_K : nullptr,
      HasU<M> ? &hessian_U : nullptr,
      &hvp_T,
      &hvp_V,
      nullptr,  // hvp_K
      nullptr,  // hvp_U
      &chin_steps,
      Adapter::analytic_energy_TTV ? &product_energy<HamiltonianForm::TTV> : nullptr,
      Adapter::analytic_energy_VVT ? &product_energy<HamiltonianForm::VVT> : nullptr,
      Adapter::has_hamiltonian_hessian ? &hvp_H : nullptr,
      NONSEP_SDK_TANGENT_KERNELS ? &chin_tangent_steps : nullptr,
      nullptr,  // value_H: a product-form model
      nullptr,  // grad_H
      &Base::gauss_steps,
  };
};

// The constant function table exported for a model class M given by H itself (hamiltonian_adapter.hpp): the
// metadata says "hamiltonian_form": "general", the table has value_H, grad_H and hvp_H (form NONSEP_FORM_GENERAL)
// and none of the entries of T, V, K, U or the kernels (plugin_abi.h version 6).
template <HamiltonianClass M, Derivatives policy, class Identity>
class HamiltonianPluginTable : PluginTableBase<HamiltonianAdapter<M, policy>> {
  using Adapter = HamiltonianAdapter<M, policy>;
  using Base = PluginTableBase<Adapter>;
  using Base::create;
  using Base::destroy;
  using Base::dimension;
  using Base::guarded;
  using Base::last_error;
  using Base::record_error;
  using typename Base::Instance;

  static std::string build_metadata() {
    auto kind = [](bool analytic) { return analytic ? "analytic" : "automatic"; };
    PluginFacts facts = Base::common_facts(Identity::value);
    facts.general_form = true;
    facts.capabilities = {{"value_H", true}, {"grad_H", true}, {"hvp_H", true}, {"gauss_steps", true}};
    facts.derivatives = {{"grad_H", kind(Adapter::analytic_grad_H)}, {"hvp_H", kind(Adapter::analytic_hvp_H)}};
    facts.automatic_differentiation = hamiltonian_differentiation_text<Adapter>();
    return metadata_text(facts);
  }
  static const char* metadata_json() noexcept { return Base::template cached_metadata<&build_metadata>(); }

  static nonsep_status value_H(nonsep_instance* instance, const double* q, const double* p, double* out,
                               std::size_t count) noexcept {
    return guarded(instance, "value_H", [&](const Instance& self) {
      const std::size_t size = count * self.adapter.dimension();
      self.adapter.value_H(std::span<const double>(q, size), std::span<const double>(p, size),
                           std::span<double>(out, count), count);
    });
  }
  static nonsep_status grad_H(nonsep_instance* instance, const double* q, const double* p, double* dH_dq, double* dH_dp,
                              std::size_t count) noexcept {
    return guarded(instance, "grad_H", [&](const Instance& self) {
      const std::size_t size = count * self.adapter.dimension();
      self.adapter.grad_H(std::span<const double>(q, size), std::span<const double>(p, size),
                          std::span<double>(dH_dq, size), std::span<double>(dH_dp, size), count);
    });
  }
  // The Hessian of H times (dq, dp); a form other than NONSEP_FORM_GENERAL is NONSEP_UNSUPPORTED.
  static nonsep_status hvp_H(nonsep_instance* instance, std::uint32_t form, const double* q, const double* p,
                             const double* dq, const double* dp, double* out_q, double* out_p,
                             std::size_t count) noexcept {
    if (instance != nullptr && form != NONSEP_FORM_GENERAL) {
      record_error(*instance, "hvp_H: form " + std::to_string(form) +
                                  " of a model given by H itself (expected NONSEP_FORM_GENERAL, 2)");
      return NONSEP_UNSUPPORTED;
    }
    return guarded(instance, "hvp_H", [&](const Instance& self) {
      const std::size_t size = count * self.adapter.dimension();
      self.adapter.hvp_H(HamiltonianForm::TTV, std::span<const double>(q, size), std::span<const double>(p, size),
                         std::span<const double>(dq, size), std::span<const double>(dp, size),
                         std::span<double>(out_q, size), std::span<double>(out_p, size), count);
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
      nullptr,  // grad_T
      nullptr,  // grad_V
      nullptr,  // value_T
      nullptr,  // value_V
      nullptr,  // hessian_T
      nullptr,  // hessian_V
      &last_error,
      nullptr,  // d3T
      nullptr,  // d3V
      nullptr,  // grad_K
      nullptr,  // grad_U
      nullptr,  // value_K
      nullptr,  // value_U
      nullptr,  // hessian_K
      nullptr,  // hessian_U
      nullptr,  // hvp_T
      nullptr,  // hvp_V
      nullptr,  // hvp_K
      nullptr,  // hvp_U
      nullptr,  // chin_steps
      nullptr,  // energy_TTV
      nullptr,  // energy_VVT
      &hvp_H,
      nullptr,  // chin_tangent_steps
      &value_H,
      &grad_H,
      &Base::gauss_steps,
  };
};

}  // namespace nonsep::sdk

// Symbols a plugin exports (everything else stays hidden).
#define NONSEP_PLUGIN_EXPORT __attribute__((visibility("default")))

// Exports model class `Model` as this library's plugin, with analytic derivatives where the class has them.
// The other four arguments are string literals: `name`, which must equal the file's stem and so the CMake target
// of nonsep_add_model (the host refuses a plugin whose metadata names another file); `version` of the model;
// `description`, one line for `nonsep models`; `hamiltonian`, what T, V and the solved H are, in words.
#define NONSEP_EXPORT_MODEL(Model, name, version, description, hamiltonian)                                      \
  NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Model, ::nonsep::sdk::Derivatives::preferred, name, version, description, \
                                       hamiltonian)

// Exports model class `Model` given by H(q, p) itself (nonsep/sdk/hamiltonian_adapter.hpp) as this library's plugin,
// with the same four strings as NONSEP_EXPORT_MODEL (`hamiltonian`: what H is, in words). Such a plugin carries no
// stepping kernels: Chin's schemes need the product form, and the host refuses them for it.
#if NONSEP_SDK_KERNEL_UNIT != 0
#define NONSEP_EXPORT_HAMILTONIAN(Model, name, version, description, hamiltonian)
#else
#define NONSEP_EXPORT_HAMILTONIAN(Model, name, version, description, hamiltonian)                           \
  namespace {                                                                                               \
  struct nonsep_exported_model_identity {                                                                   \
    static constexpr ::nonsep::sdk::ModelIdentity value{name, version, description, hamiltonian};           \
  };                                                                                                        \
  }                                                                                                         \
  NONSEP_DEFINE_PLUGIN((::nonsep::sdk::HamiltonianPluginTable<Model, ::nonsep::sdk::Derivatives::preferred, \
                                                              nonsep_exported_model_identity>::api))
#endif

// As NONSEP_EXPORT_MODEL, choosing the derivative policy (::nonsep::sdk::Derivatives::automatic ignores the
// class's analytic derivatives; used to compare the two).
#if NONSEP_SDK_KERNEL_UNIT != 0  // a unit of the wider kernels alone (kernels.hpp)
#define NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Model, policy, name, version, description, hamiltonian) \
  NONSEP_SDK_DEFINE_KERNEL_UNIT(::nonsep::sdk::ModelAdapter<Model, policy>)
#else
#define NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Model, policy, name, version, description, hamiltonian) \
  namespace {                                                                                        \
  struct nonsep_exported_model_identity {                                                            \
    static constexpr ::nonsep::sdk::ModelIdentity value{name, version, description, hamiltonian};    \
  };                                                                                                 \
  }                                                                                                  \
  NONSEP_DEFINE_PLUGIN((::nonsep::sdk::PluginTable<Model, policy, nonsep_exported_model_identity>::api))
#endif
