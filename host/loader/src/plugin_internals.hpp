#pragma once
// Internal to nonsep::loader (host/loader/src/): what a Plugin and a PluginModel hold, shared by the loader
// (plugin_loader.cpp), the metadata checks (plugin_metadata.cpp) and the evaluations (plugin_model.cpp).
#include <boost/shared_ptr.hpp>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"

namespace nonsep::host {

struct Plugin::Loaded {
  boost::shared_ptr<const nonsep_plugin_api> table;  // from import_alias: owns the loaded library
  std::filesystem::path path;
  // The plugin's table as one of this host's version: an older table copied, with the entries it lacks null.
  nonsep_plugin_api entries{};
  unsigned abi_version = NONSEP_PLUGIN_ABI_VERSION;  // the plugin's own
  const nonsep_plugin_api* api = nullptr;            // &entries
  nlohmann::json metadata;
  KernelChoice kernels;
  bool general = false;  // the metadata's "hamiltonian_form" is "general": a model given by H(q, p) itself
};

struct PluginModel::Instance {
  Plugin plugin;  // keeps the library loaded while the instance lives
  const nonsep_plugin_api* api = nullptr;
  nonsep_instance* handle = nullptr;
  std::size_t dimension = 0;
  nlohmann::json parameters;
  std::uint64_t kernel_calls = 0;

  Instance() = default;
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;
  ~Instance() {
    if (handle != nullptr) api->destroy(handle);
  }
};

// A path in quotes, as the loader's messages name files.
inline std::string quoted(const std::filesystem::path& path) {
  return std::string("'").append(path.string()).append("'");
}

// "ok", "invalid parameters", ...: a status of plugin_abi.h as words.
const char* status_name(nonsep_status status);

// The kernel this process uses of the plugin of ABI version `abi_version` with checked metadata `metadata` and table
// `api` (kernel_choice.cpp). Throws PluginError when NONSEP_INSTRUCTION_SET asks for one it cannot have.
KernelChoice choose_kernel(const nlohmann::json& metadata, const nonsep_plugin_api& api, unsigned abi_version);
// NONSEP_INSTRUCTION_SET as the kernel choice reads it ("x86-64" for "baseline"; "" when unset).
std::string instruction_set_pin();

// The metadata checks of plugin_abi.h on the parsed metadata `m` of the plugin at `path` whose table is `api`, of ABI
// version `abi_version`, including the functions its kind of model requires (plugin_abi.h, check 3: grad_T and grad_V
// for the product form, value_H and grad_H for a general H). Throws PluginError naming the field or the function.
void check_metadata(const nlohmann::json& m, const nonsep_plugin_api& api, unsigned abi_version,
                    const std::filesystem::path& path);

}  // namespace nonsep::host
