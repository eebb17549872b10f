// A plugin of ABI version 4 (whose metadata gave the kernel version) claiming stepping kernels of another kernel
// version (999): the host must step it through its evaluations, with a note saying why. Its table is the SDK's cut to
// version 4's size, with the metadata function replaced.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <nonsep/plugin_sdk.hpp>
#include <string>

#include "paper1d/paper1d.hpp"

namespace {

struct Identity {
  static constexpr nonsep::sdk::ModelIdentity value{"kernel_other_version", "0.1",
                                                    "test plugin: paper1d with kernels of another version",
                                                    "T = p + p^3/6, V = q^2/2 + q^4/12"};
};
using Table = nonsep::sdk::PluginTable<Paper1D, nonsep::sdk::Derivatives::preferred, Identity>;

const char* metadata() {
  static const std::string text = [] {
    auto metadata = nlohmann::json::parse(Table::api.metadata_json());
    metadata["kernels"]["version"] = 999;
    metadata["capabilities"]["hvp_H"] = false;  // past version 4's table
    metadata["capabilities"]["chin_tangent_steps"] = false;
    metadata["capabilities"]["gauss_steps"] = false;
    return metadata.dump();
  }();
  return text.c_str();
}

nonsep_plugin_api with_other_metadata() {
  nonsep_plugin_api api = Table::api;
  api.abi_version = 4;
  api.struct_size = static_cast<std::uint32_t>(NONSEP_PLUGIN_V4_STRUCT_SIZE);
  api.metadata_json = metadata;
  return api;
}

const nonsep_plugin_api table = with_other_metadata();

}  // namespace

NONSEP_DEFINE_PLUGIN(table);
