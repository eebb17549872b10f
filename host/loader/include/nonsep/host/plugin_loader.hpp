#pragma once
// Host side of the plugin boundary: finding, loading and checking plugins (plugin_abi.h), and PluginModel, which
// puts a plugin instance behind the core's model interface (nonsep/core/model.hpp).
//
// Naming and search. A plugin file is `<name>.so`. `load_plugin(spec, base)` treats `spec` as a path when it
// contains a '/' or ends in ".so" (relative paths resolve against `base`, the job file's folder); otherwise as a
// name, looked up as `<dir>/<name>.so` in plugin_search_path(): the directories of NONSEP_PLUGIN_PATH (':'
// separated), then the install's plugin directory (<prefix>/lib/nonsep/plugins, found relative to the running
// executable), then the build tree's (build/plugins). A failure lists every place tried and the loader's text.
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
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "nonsep/core/error.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/core/phase_space_batch.hpp"

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

class Plugin {
 public:
  const std::filesystem::path& path() const;
  // The metadata JSON of plugin_abi.h, parsed and checked.
  const nlohmann::json& metadata() const;
  std::string name() const;
  std::string version() const;
  std::string description() const;
  std::vector<PluginParameter> parameters() const;
  bool has_hessians() const;  // both hessian_T and hessian_V
  bool has_values() const;    // both value_T and value_V
  bool has_integrate() const; // the fused stepping loop integrate() (ABI version 2, optional)

  // Creates an instance. `parameters` must be a JSON object; unknown names, wrong types and values out of range
  // are refused with a PluginError naming the parameter (checked by the host against the metadata first, then by
  // the plugin's create()).
  PluginModel create(const nlohmann::json& parameters) const;

 private:
  friend Plugin load_plugin(const std::string&, const std::filesystem::path&);
  struct Loaded;
  std::shared_ptr<const Loaded> loaded_;
};

// Throws PluginError: file not found (listing every place tried), not a shared library, no plugin symbol,
// ABI version mismatch (also a version-1 plugin, recognised by its entry function), wrong table size, invalid metadata.
Plugin load_plugin(const std::string& name_or_path, const std::filesystem::path& base_directory);

std::vector<std::filesystem::path> plugin_search_path();

// Every `*.so` in the search path that loads as a plugin, first one of each name wins; and those that fail, with
// their error, so `nonsep models` can show both.
struct DiscoveredPlugin {
  std::filesystem::path path;
  std::optional<Plugin> plugin;  // empty when loading failed
  std::string error;
};
std::vector<DiscoveredPlugin> discover_plugins();

// A plugin instance as a nonsep::ModelWithHessians. One instance must be used by one thread at a time.
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

  // The fused path (plugin_abi.h integrate): whether the plugin has it, and `steps` steps of dt on x with
  // `integrator`'s scheme run inside the plugin. integrator's first-same-as-last cache goes in and comes back
  // and the plugin's evaluations are added to its counts, so stepping on with `integrator` gives what stepping
  // with it all along would have. Throws nonsep::ModelError when the plugin lacks integrate or fails (x and the
  // integrator's cache are then unspecified: the caller goes back to a copy).
  bool can_integrate() const;
  void integrate(Integrator& integrator, PhaseSpaceBatch& x, double dt, std::uint64_t steps) const;

  const Plugin& plugin() const;
  // The parameters in effect: the metadata's defaults overlaid with those given to create().
  const nlohmann::json& parameters() const;

 private:
  friend class Plugin;
  struct Instance;
  std::shared_ptr<Instance> instance_;
};

}  // namespace nonsep::host
