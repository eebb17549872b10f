// Loading and checking plugins (plugin_loader.hpp). Every check that can fail produces its own PluginError
// message naming the file, what was expected and what was found; the library is unloaded only after every
// Plugin and PluginModel from it is gone.
#include "nonsep/host/plugin_loader.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <boost/dll/import.hpp>
#include <boost/dll/runtime_symbol_info.hpp>
#include <boost/dll/shared_library.hpp>
#include <boost/shared_ptr.hpp>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <set>
#include <sstream>
#include <system_error>
#include <vector>

#include "nonsep/plugin_abi.h"
#include "nonsep/sdk/parameter_rules.hpp"
#include "plugin_internals.hpp"

namespace nonsep::host {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The remedy for a plugin of another ABI version, named in both version refusals.
const std::string rebuild_hint =
    "rebuild the plugin against the installed SDK (find_package(nonsep) and nonsep_add_model, or the headers of "
    "this nonsep's include/nonsep/plugin_abi.h)";

// The versions this host loads, as its refusals name them, and the table sizes of each (plugin_abi.h; none for a
// version it does not load). The first size is the version's own; versions 4 and 6 also load a shorter edition.
const std::string accepted_versions = std::to_string(NONSEP_PLUGIN_ABI_VERSION) + ", 5, 4 or 3";
std::vector<std::size_t> table_sizes(std::uint32_t version) {
  switch (version) {
    case NONSEP_PLUGIN_ABI_VERSION:
      return {NONSEP_PLUGIN_V6_STRUCT_SIZE, NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE};
    case 5:
      return {NONSEP_PLUGIN_V5_STRUCT_SIZE};
    case 4:
      return {NONSEP_PLUGIN_V4_STRUCT_SIZE, NONSEP_PLUGIN_V4_KERNEL_STRUCT_SIZE};
    case 3:
      return {NONSEP_PLUGIN_V3_STRUCT_SIZE};
    default:
      return {};
  }
}

bool looks_like_path(const std::string& spec) {
  return spec.find('/') != std::string::npos || (spec.size() > 3 && spec.compare(spec.size() - 3, 3, ".so") == 0);
}

}  // namespace

std::vector<fs::path> plugin_search_path() {
  std::vector<fs::path> directories;
  auto add = [&](const fs::path& directory) {
    const fs::path normal = directory.lexically_normal();
    if (std::find(directories.begin(), directories.end(), normal) == directories.end()) directories.push_back(normal);
  };
  if (const char* variable = std::getenv("NONSEP_PLUGIN_PATH")) {
    std::stringstream entries(variable);
    std::string entry;
    while (std::getline(entries, entry, ':'))
      if (!entry.empty()) add(fs::absolute(entry));
  }
  std::error_code error;
  const fs::path executable = boost::dll::program_location(error);
  if (!error) {
    const fs::path bin = executable.parent_path();
    add(bin / NONSEP_PLUGIN_DIR_FROM_EXECUTABLE);
    // Only in a build tree (build/bin/nonsep, build/CMakeCache.txt), never beside an installed bin/.
    if (fs::is_regular_file(bin / NONSEP_BUILD_ROOT_FROM_EXECUTABLE / "CMakeCache.txt", error))
      add(bin / NONSEP_BUILD_PLUGIN_DIR_FROM_EXECUTABLE);
  }
  return directories;
}

const fs::path& Plugin::path() const { return loaded_->path; }
const json& Plugin::metadata() const { return loaded_->metadata; }
std::string Plugin::name() const { return loaded_->metadata["name"].get<std::string>(); }
std::string Plugin::version() const { return loaded_->metadata["version"].get<std::string>(); }
std::string Plugin::description() const { return loaded_->metadata["description"].get<std::string>(); }
bool Plugin::has_hessians() const {
  const nonsep_plugin_api& api = *loaded_->api;
  return api.hessian_T != nullptr && api.hessian_V != nullptr && (api.grad_K == nullptr || api.hessian_K != nullptr) &&
         (api.grad_U == nullptr || api.hessian_U != nullptr);
}
bool Plugin::general_hamiltonian() const { return loaded_->general; }
bool Plugin::has_energy() const { return general_hamiltonian() || has_hessians(); }
bool Plugin::has_K() const { return loaded_->api->grad_K != nullptr; }
bool Plugin::has_U() const { return loaded_->api->grad_U != nullptr; }
bool Plugin::has_hamiltonian_hessian_products() const { return loaded_->api->hvp_H != nullptr; }
bool Plugin::has_third_derivatives() const { return loaded_->api->d3T != nullptr && loaded_->api->d3V != nullptr; }
bool Plugin::has_hessian_vector_products() const {
  return loaded_->api->hvp_T != nullptr && loaded_->api->hvp_V != nullptr;
}
bool Plugin::has_product_energy(HamiltonianForm form) const {
  return (form == HamiltonianForm::TTV ? loaded_->api->energy_TTV : loaded_->api->energy_VVT) != nullptr;
}
unsigned Plugin::abi_version() const { return loaded_->abi_version; }
const KernelChoice& Plugin::kernels() const { return loaded_->kernels; }
bool Plugin::thread_safe() const { return loaded_->metadata["thread_safe"].get<bool>(); }
bool Plugin::has_values() const { return loaded_->api->value_T != nullptr && loaded_->api->value_V != nullptr; }

std::vector<PluginParameter> Plugin::parameters() const {
  std::vector<PluginParameter> result;
  for (const json& p : loaded_->metadata["parameters"]) {
    PluginParameter parameter;
    parameter.name = p["name"].get<std::string>();
    parameter.type = p["type"].get<std::string>();
    parameter.default_value = p["default"];
    if (p.contains("minimum")) parameter.minimum = p["minimum"].get<double>();
    if (p.contains("maximum")) parameter.maximum = p["maximum"].get<double>();
    parameter.unit = p.value("unit", "");
    parameter.description = p.value("description", "");
    result.push_back(std::move(parameter));
  }
  return result;
}

PluginModel Plugin::create(const json& parameters_or_null) const {
  const std::string who = "plugin '" + name() + "' (" + path().string() + ")";
  // A JSON null (what `create({})` builds in nlohmann::json) means no parameters given.
  const json given = parameters_or_null.is_null() ? json::object() : parameters_or_null;
  if (!given.is_object())
    throw PluginError(who + ": the parameters must be a JSON object such as {\"name\": value} (found " +
                      std::string(given.type_name()) + ")");
  const auto declared = parameters();
  json effective;
  try {
    effective = sdk::checked_parameters(
        std::span<const PluginParameter>(declared), given, [](const PluginParameter& p) { return p.type; },
        [](const PluginParameter& p) { return p.default_value; });
  } catch (const sdk::InvalidParameter& refused) {
    throw PluginError(who + ": " + refused.what());
  }

  const nonsep_plugin_api& api = *loaded_->api;
  auto instance = std::make_shared<PluginModel::Instance>();
  instance->plugin = *this;
  instance->api = &api;
  instance->parameters = effective;
  char message[1024] = {};
  const std::string text = effective.dump();
  const nonsep_status status = api.create(text.c_str(), &instance->handle, message, sizeof message);
  message[sizeof message - 1] = '\0';
  if (status != NONSEP_OK) {
    if (instance->handle != nullptr) api.destroy(instance->handle);
    instance->handle = nullptr;
    throw PluginError(who + " could not create a model (" + status_name(status) +
                      "): " + (message[0] ? message : "the plugin gave no message"));
  }
  if (instance->handle == nullptr) throw PluginError(who + ": create() reported success but returned no instance");

  instance->dimension = api.dimension(instance->handle);
  if (instance->dimension == 0)
    throw PluginError(who +
                      ": the instance has dimension 0 (the ABI requires at least one degree of freedom; "
                      "check the parameters that set the dimension)");
  const json& dimension = loaded_->metadata["dimension"];
  const std::size_t expected = dimension.contains("fixed")
                                   ? dimension["fixed"].get<std::size_t>()
                                   : effective[dimension["parameter"].get<std::string>()].get<std::size_t>();
  if (instance->dimension != expected)
    throw PluginError(who + ": the instance has dimension " + std::to_string(instance->dimension) +
                      " but the metadata implies " + std::to_string(expected) + " (expected " +
                      std::to_string(expected) + ", found " + std::to_string(instance->dimension) + ")");
  PluginModel model;
  model.instance_ = std::move(instance);
  return model;
}

Plugin load_plugin(const std::string& name_or_path, const fs::path& base_directory) {
  if (name_or_path.empty()) throw PluginError("no plugin given (an empty name)");
  fs::path file;
  if (looks_like_path(name_or_path)) {
    const fs::path given(name_or_path);
    file = (given.is_absolute() ? given : base_directory / given).lexically_normal();
    std::error_code error;
    const fs::file_status status = fs::status(file, error);
    if (!fs::is_regular_file(status)) {
      const std::string what = !fs::exists(status)        ? "does not exist"
                               : fs::is_directory(status) ? "is a folder, not a shared library"
                               : fs::is_fifo(status)      ? "is a FIFO (named pipe), not a shared library"
                               : fs::is_character_file(status) || fs::is_block_file(status)
                                   ? "is a device, not a shared library"
                                   : "is not a regular file, so not a shared library";
      throw PluginError("plugin file " + quoted(file) + " " + what +
                        (given.is_absolute() ? std::string()
                                             : " (" + quoted(given) + " relative to " + quoted(base_directory) + ")"));
    }
  } else {
    std::string tried;
    for (const fs::path& directory : plugin_search_path()) {
      const fs::path candidate = directory / (name_or_path + ".so");
      std::error_code error;
      if (fs::is_regular_file(candidate, error)) {
        file = candidate;
        break;
      }
      tried += "\n  " + candidate.string() + " (no such file)";
    }
    if (file.empty())
      throw PluginError("plugin '" + name_or_path +
                        "' not found; looked in NONSEP_PLUGIN_PATH, the install's "
                        "plugin folder and the build tree's, trying:" +
                        tried);
  }
  return load_plugin_file(file, file);
}

Plugin load_plugin_file(const fs::path& load_from, const fs::path& path) {
  // The checks of plugin_abi.h, in its order.
  auto loaded = std::make_shared<Plugin::Loaded>();
  loaded->path = path;
  boost::dll::shared_library library;
  try {
    library.load(load_from, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local);
  } catch (const std::exception& e) {
    throw PluginError("cannot load " + quoted(path) + " as a shared library: " + e.what());
  }
  if (!library.has(NONSEP_PLUGIN_SYMBOL)) {
    if (library.has(NONSEP_PLUGIN_V1_ENTRY_SYMBOL))
      throw PluginError("plugin " + quoted(path) +
                        " uses plugin ABI version 1 (it exports '" NONSEP_PLUGIN_V1_ENTRY_SYMBOL
                        "') but this host uses version " +
                        std::to_string(NONSEP_PLUGIN_ABI_VERSION) + " (expected " + accepted_versions + ", found 1); " +
                        rebuild_hint);
    throw PluginError(
        quoted(path) +
        " is a shared library but not a nonsep plugin: it does not export the symbol '" NONSEP_PLUGIN_SYMBOL
        "' (define it with NONSEP_EXPORT_MODEL, see plugin_sdk.hpp, or "
        "NONSEP_DEFINE_PLUGIN, see plugin_abi.h)");
  }
  // The symbol is a pointer to the table; import_alias returns the table as a shared_ptr that owns the library.
  loaded->table = boost::dll::import_alias<const nonsep_plugin_api>(std::move(library), NONSEP_PLUGIN_SYMBOL);
  const nonsep_plugin_api* api = loaded->table.get();
  if (api == nullptr)
    throw PluginError("the symbol '" NONSEP_PLUGIN_SYMBOL "' of plugin " + quoted(path) + " is a null table");
  // A library that exports the table itself under the symbol, instead of a pointer to it, would have its first
  // bytes (abi_version, struct_size) read as an address: refuse any pointer that is not a suitably aligned
  // address inside a loaded library before reading through it.
  Dl_info where{};
  const auto address = reinterpret_cast<std::uintptr_t>(api);
  if (address % alignof(nonsep_plugin_api) != 0 || ::dladdr(api, &where) == 0) {
    std::ostringstream found;
    found << std::hex << "0x" << address;
    throw PluginError("the symbol '" NONSEP_PLUGIN_SYMBOL "' of plugin " + quoted(path) +
                      " does not point to a table in a loaded library (it holds " + found.str() +
                      "): it must be a pointer to a statically allocated table, 'const nonsep_plugin_api* const "
                      "nonsep_plugin = &table;', not the table itself; define it with NONSEP_EXPORT_MODEL (see "
                      "plugin_sdk.hpp) or NONSEP_DEFINE_PLUGIN (see plugin_abi.h)");
  }
  const std::uint32_t version = api->abi_version;
  const std::vector<std::size_t> sizes = table_sizes(version);
  if (sizes.empty())
    throw PluginError("plugin " + quoted(path) + " uses plugin ABI version " + std::to_string(version) +
                      " but this host uses version " + std::to_string(NONSEP_PLUGIN_ABI_VERSION) + " (expected " +
                      accepted_versions + ", found " + std::to_string(version) + "); " + rebuild_hint);
  if (std::find(sizes.begin(), sizes.end(), api->struct_size) == sizes.end()) {
    std::string defined;
    for (const std::size_t size : sizes) defined += (defined.empty() ? "" : " or ") + std::to_string(size);
    throw PluginError("plugin " + quoted(path) + " has a function table of " + std::to_string(api->struct_size) +
                      " bytes but ABI version " + std::to_string(version) + " defines " + defined + " (expected " +
                      std::to_string(sizes.front()) + ", found " + std::to_string(api->struct_size) +
                      "); the plugin was built against a different plugin_abi.h");
  }
  std::memcpy(&loaded->entries, api, api->struct_size);  // the entries a shorter table lacks stay null
  loaded->abi_version = version;
  api = &loaded->entries;
  const std::pair<const char*, bool> required[] = {{"metadata_json", api->metadata_json != nullptr},
                                                   {"create", api->create != nullptr},
                                                   {"destroy", api->destroy != nullptr},
                                                   {"dimension", api->dimension != nullptr},
                                                   {"last_error", api->last_error != nullptr}};
  for (const auto& [function, present] : required)
    if (!present)
      throw PluginError("plugin " + quoted(path) + " lacks the required function " + function +
                        " (its table entry is null)");
  const char* text = api->metadata_json();
  if (text == nullptr) throw PluginError("plugin " + quoted(path) + " returned null metadata");
  try {
    loaded->metadata = json::parse(text);
  } catch (const json::parse_error& e) {
    const std::string shown = std::string(text).substr(0, 80);
    throw PluginError("the metadata of plugin " + quoted(path) + " is not valid JSON: " + e.what() +
                      " (metadata begins: \"" + shown + "\")");
  }
  check_metadata(loaded->metadata, *api, version, path);
  loaded->general = loaded->metadata.value("hamiltonian_form", "product") == "general";
  loaded->api = &loaded->entries;
  loaded->kernels = choose_kernel(loaded->metadata, *loaded->api, version);
  Plugin plugin;
  plugin.loaded_ = std::move(loaded);
  return plugin;
}

std::vector<DiscoveredPlugin> discover_plugins() {
  std::vector<DiscoveredPlugin> found;
  std::set<std::string> names;
  for (const fs::path& directory : plugin_search_path()) {
    std::error_code error;
    if (!fs::is_directory(directory, error)) continue;
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(directory, error))
      if (entry.path().extension() == ".so") files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
      if (!names.insert(file.stem().string()).second) continue;
      DiscoveredPlugin discovered{file, std::nullopt, ""};
      try {
        discovered.plugin = load_plugin(file.string(), directory);
      } catch (const PluginError& e) {
        discovered.error = e.what();
      }
      found.push_back(std::move(discovered));
    }
  }
  return found;
}

}  // namespace nonsep::host
