#pragma once
// Host side of the plugin boundary: finding, loading and checking plugins (plugin_abi.h), and PluginModel, which
// puts a plugin instance behind the core's model interface (nonsep/core/base/model.hpp).
//
// Naming and search. A plugin file is `<name>.so`. `load_plugin(spec, base)` treats `spec` as a path when it
// contains a '/' or ends in ".so" (relative paths resolve against `base`, the job file's folder); otherwise as a
// name, looked up as `<dir>/<name>.so` in plugin_search_path(): the directories of NONSEP_PLUGIN_PATH (':'
// separated), then the install's plugin directory (<prefix>/lib/nonsep/plugins), then, for an executable of a
// build tree, the build tree's (build/plugins); both are found relative to the running executable, so no path of
// the building machine is compiled in. A failure lists every place tried and the loader's text.
//
// Lifetime. Plugin and PluginModel share ownership of the loaded library (boost::dll::shared_library, loaded with
// RTLD_NOW so unresolved symbols fail at load time); the library stays loaded while any of them is alive.
//
// Errors. Everything that fails before a run starts throws PluginError with a complete message (which plugin,
// which file, what was expected and found). Evaluation failures during a run throw nonsep::ModelError with the
// plugin's own message.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/kernel/chin_stages.hpp"
#include "nonsep/core/kernel/chin_tangent_stages.hpp"
#include "nonsep/core/kernel/gauss_stages.hpp"

struct nonsep_plugin_api;
struct nonsep_instance;

namespace nonsep::host {

class PluginError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PluginParameter {
  std::string name;
  std::string type;  // "integer", "number" or "boolean"
  nlohmann::json default_value;
  std::optional<double> minimum, maximum;
  std::string unit, description;
};

class PluginModel;

// A plugin's stepping kernels (plugin_abi.h chin_steps) and the one this process uses. Chosen when the plugin is
// loaded: none when the plugin has none or was built against another kernel version (with a note saying so);
// otherwise the instruction set NONSEP_INSTRUCTION_SET names ("baseline" for x86-64; "evaluation" for none), or
// without it the widest of the plugin's that this processor runs.
struct KernelChoice {
  bool present = false;                       // the plugin carries kernels
  std::uint64_t version = 0;                  // the kernel version it was built with (version 5: the one it implies)
  std::vector<std::string> instruction_sets;  // as the metadata lists them (index 0 the baseline)
  std::vector<bool> usable;                   // per instruction set: right kernel version, and this processor runs it
  std::optional<std::size_t> chosen;          // the index used; empty: the evaluation path
  std::string note;                           // how the choice was made, or why none is used
  // The chosen instruction set's name, or "" for the evaluation path.
  std::string chosen_name() const { return chosen ? instruction_sets[*chosen] : ""; }
};

// The instruction set a plugin with the kernels `names` would run here, by the same rule: NONSEP_INSTRUCTION_SET's
// ("x86-64" for "baseline", "" for "evaluation"), else the widest of `names` this processor runs. Formula models
// compile this one besides the baseline (host/include/nonsep/host/formula/plugin_cache.hpp).
std::string instruction_set_to_use(const std::vector<std::string>& names);

class Plugin {
 public:
  const std::filesystem::path& path() const;
  // The metadata JSON of plugin_abi.h, parsed and checked.
  const nlohmann::json& metadata() const;
  std::string name() const;
  std::string version() const;
  std::string description() const;
  std::vector<PluginParameter> parameters() const;
  // Whether the plugin is a model given by H(q, p) itself (plugin_abi.h version 6, "hamiltonian_form": "general"):
  // it has value_H, grad_H (and hvp_H) and none of T, V, K, U; only the schemes that integrate H take it.
  bool general_hamiltonian() const;
  // Whether H itself can be evaluated (the energy, energy shells, `measure` "energy"): a general plugin's value_H, or
  // a product-form plugin's Hessians.
  bool has_energy() const;
  // hessian_T and hessian_V, and the Hessians of the separable parts the plugin has (hessian_K with grad_K,
  // hessian_U with grad_U): what the energy and the tangent maps need.
  bool has_hessians() const;
  bool has_values() const;             // both value_T and value_V
  bool has_third_derivatives() const;  // both d3T and d3V
  // hvp_H (plugin_abi.h version 5): the directional derivative of grad H the comparators' tangent maps need.
  bool has_hamiltonian_hessian_products() const;
  // The separable part K(p) + U(q) of the solved H (plugin_abi.h version 4): grad_K (resp. grad_U) present. The
  // loader has checked that its value is too.
  bool has_K() const;
  bool has_U() const;
  // Both hvp_T and hvp_V.
  bool has_hessian_vector_products() const;
  // energy_TTV (resp. energy_VVT): the plugin writes out the product term of H in that form.
  bool has_product_energy(HamiltonianForm form) const;
  // The plugin ABI version its table was built for (6, or 5, 4 or 3 for an older table without the later entries).
  unsigned abi_version() const;
  // The metadata's "thread_safe": false means one instance, used on one thread, for a whole run (plugin_abi.h).
  bool thread_safe() const;
  const KernelChoice& kernels() const;

  // Creates an instance. `parameters` must be a JSON object; unknown names, wrong types and values out of range
  // are refused with a PluginError naming the parameter (checked by the host against the metadata first, then by
  // the plugin's create()).
  PluginModel create(const nlohmann::json& parameters) const;

 private:
  friend Plugin load_plugin_file(const std::filesystem::path&, const std::filesystem::path&);
  struct Loaded;
  std::shared_ptr<const Loaded> loaded_;
};

// Throws PluginError: NONSEP_INSTRUCTION_SET naming an instruction set the plugin lacks or this processor cannot
// run; file not found (listing every place tried), not a shared library, no plugin symbol,
// ABI version mismatch (also a version-1 plugin, recognised by its entry function; both say "expected 6, 5, 4 or 3,
// found N" and to rebuild against the installed SDK), wrong table size, a required function missing, invalid metadata
// (including capabilities that disagree with the table and a missing "thread_safe").
Plugin load_plugin(const std::string& name_or_path, const std::filesystem::path& base_directory);

// Loads the plugin file that `load_from` names (the name the dynamic loader opens, such as /proc/self/fd/N for a file
// held open and checked) as the plugin at `path` (Plugin::path, messages); what load_plugin does once it has found
// the file, with the same checks and errors.
Plugin load_plugin_file(const std::filesystem::path& load_from, const std::filesystem::path& path);

std::vector<std::filesystem::path> plugin_search_path();

// Every `*.so` in the search path that loads as a plugin, first one of each name wins; and those that fail, with
// their error, so `nonsep models` can show both.
struct DiscoveredPlugin {
  std::filesystem::path path;
  std::optional<Plugin> plugin;  // empty when loading failed
  std::string error;
};
std::vector<DiscoveredPlugin> discover_plugins();

// A plugin instance as a nonsep::ModelWithThirdDerivatives and a nonsep::ModelWithSeparablePart (has_K() and
// has_U() say whether the plugin has K and U; a model without them is the pure product form), and as a
// nonsep::ModelWithGeneralHamiltonian (general_hamiltonian() says whether the plugin is given by H itself: then its
// value_H, grad_H and hvp_H serve, and the functions of T, V, K and U throw). One instance must be used by one thread
// at a time.
class PluginModel {
 public:
  std::size_t dimension() const;
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const;
  // Throw nonsep::ModelError when the plugin lacks the function, or it fails.
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const;
  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const;

  // Directional third derivatives (plugin_abi.h d3T, d3V): u has the layout of x, out receives count*n numbers.
  // Throw nonsep::ModelError when the plugin lacks the function, or it fails.
  void d3T(std::span<const double> p, std::span<const double> u, std::span<double> out, std::size_t count) const;
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const;
  // Hessian-vector products (plugin_abi.h hvp_T, hvp_V): out[b*n+i] = sum_j X_ij(x_b) v[b*n+j]. Throw
  // nonsep::ModelError when the plugin lacks the function, or it fails.
  void hvp_T(std::span<const double> p, std::span<const double> v, std::span<double> out, std::size_t count) const;
  void hvp_V(std::span<const double> q, std::span<const double> v, std::span<double> out, std::size_t count) const;
  // Whether the plugin has both products (the core's energy and gradient of H use them then: hessian_products.hpp).
  bool has_hessian_vector_products() const;
  // The directional derivative of grad H (plugin_abi.h hvp_H, version 5): out_q = d(dH/dq), out_p = d(dH/dp) along
  // (dq, dp), every span count*n numbers; as a core model a nonsep::ModelWithHamiltonianHessian
  // (hamiltonian_gradient.hpp), whose has_hamiltonian_hessian_products says whether the plugin has it. Throws
  // nonsep::ModelError when the plugin lacks it, or it fails.
  void hvp_H(HamiltonianForm form, std::span<const double> q, std::span<const double> p, std::span<const double> dq,
             std::span<const double> dp, std::span<double> out_q, std::span<double> out_p, std::size_t count) const;
  bool has_hamiltonian_hessian_products() const;
  // A model given by H itself (plugin_abi.h version 6): H, one number per state, and its gradient, every span count*n
  // numbers. Throw nonsep::ModelError when the plugin lacks them (a product-form plugin), or they fail.
  bool general_hamiltonian() const;
  void value_H(std::span<const double> q, std::span<const double> p, std::span<double> out, std::size_t count) const;
  void grad_H(std::span<const double> q, std::span<const double> p, std::span<double> dH_dq, std::span<double> dH_dp,
              std::size_t count) const;
  // The product term of H in `form` (plugin_abi.h energy_TTV, energy_VVT), one number per state into out: as a
  // core model a nonsep::ModelWithProductEnergy (energy.hpp), whose EnergyEvaluator uses it where the plugin has it.
  // Throws nonsep::ModelError when the plugin lacks it, or it fails.
  bool has_product_energy(HamiltonianForm form) const;
  void product_energy(HamiltonianForm form, std::span<const double> q, std::span<const double> p, std::span<double> out,
                      std::size_t count) const;
  // The same instance, whose has_product_energy is false: H from the products or the Hessians (`inspect --check`
  // compares the two).
  PluginModel without_product_energy() const;

  // The separable part (model.hpp). Throw nonsep::ModelError when the plugin lacks the function, or it fails.
  bool has_K() const;
  bool has_U() const;
  void grad_K(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void grad_U(std::span<const double> q, std::span<double> out, std::size_t count) const;
  void value_K(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void value_U(std::span<const double> q, std::span<double> out, std::size_t count) const;
  void hessian_K(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void hessian_U(std::span<const double> q, std::span<double> out, std::size_t count) const;

  // The same instance, whose chin_steps uses the plugin's chosen kernel (Plugin::kernels()); the evaluation path's
  // model (this one, and every PluginModel from create()) answers chin_steps with false. As a core model it is a
  // nonsep::ModelWithChinSteps (chin_stages.hpp): ChinBasicStep hands it the steps no stage observer watches.
  // With an instruction set's index: that kernel instead (none when it is not usable, KernelChoice::usable).
  PluginModel with_kernel() const;
  PluginModel with_kernel(std::size_t instruction_set) const;
  bool has_kernel() const { return kernel_.has_value(); }
  // Advances `call` through the plugin's kernel and returns true, or returns false without a kernel at hand.
  // Throws nonsep::ModelError with the plugin's message when the kernel fails.
  bool chin_steps(const ChinStepsCall& call) const;
  // Advances `call` through the plugin's tangent kernel (plugin_abi.h chin_tangent_steps, ABI version 5) with the same
  // instruction set and returns true, or returns false without one at hand. Throws as chin_steps does.
  bool chin_tangent_steps(const ChinTangentStepsCall& call) const;
  // Takes `call`'s Gauss-Legendre step through the plugin's gauss_steps (plugin_abi.h, ABI version 6: compiled with
  // the plugin's own flags) and returns true; false without it at hand (a plugin without the entry, a model not from
  // with_kernel(), NONSEP_INSTRUCTION_SET=evaluation) or when it fails inside (the caller then takes the step through
  // the evaluations, which say why). As a core model it is a nonsep::ModelWithGaussSteps (gauss_stages.hpp).
  bool gauss_steps(const GaussStepsCall& call) const;
  bool has_gauss_kernel() const { return gauss_kernel_; }
  // Calls of chin_steps, chin_tangent_steps and gauss_steps that ran a kernel, on this instance (every PluginModel
  // sharing it).
  std::uint64_t kernel_calls() const;

  const Plugin& plugin() const;
  // The parameters in effect: the metadata's defaults overlaid with those given to create().
  const nlohmann::json& parameters() const;

 private:
  friend class Plugin;
  struct Instance;
  std::shared_ptr<Instance> instance_;
  std::optional<std::uint32_t> kernel_;  // the instruction set chin_steps uses; empty: the evaluation path
  bool gauss_kernel_ = false;            // whether gauss_steps uses the plugin's
  bool product_energy_ = true;           // false: has_product_energy says no
};

}  // namespace nonsep::host
