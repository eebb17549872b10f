#pragma once
// Host side of the plugin boundary: finding, loading and checking plugins (plugin_abi.h), and PluginModel, which
// puts a plugin instance behind the core's model interface (nonsep/core/model.hpp).
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

#include "nonsep/core/error.hpp"

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
  bool has_hessians() const;           // both hessian_T and hessian_V
  bool has_values() const;             // both value_T and value_V
  bool has_third_derivatives() const;  // both d3T and d3V
  // The plugin ABI version its table was built for (4, or 3 for a table without version 4's entries).
  unsigned abi_version() const;
  // The metadata's "thread_safe": false means one instance, used on one thread, for a whole run (plugin_abi.h).
  bool thread_safe() const;

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
// ABI version mismatch (also a version-1 plugin, recognised by its entry function; both say "expected 4 or 3, found N"
// and to rebuild against the installed SDK), wrong table size, a required function missing, invalid metadata
// (including capabilities that disagree with the table and a missing "thread_safe").
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

// A plugin instance as a nonsep::ModelWithThirdDerivatives. One instance must be used by one thread at a time.
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

  const Plugin& plugin() const;
  // The parameters in effect: the metadata's defaults overlaid with those given to create().
  const nlohmann::json& parameters() const;

 private:
  friend class Plugin;
  struct Instance;
  std::shared_ptr<Instance> instance_;
};

}  // namespace nonsep::host
