#pragma once
// A plugin's metadata (plugin_abi.h, metadata_json) as an SDK table describes it: PluginFacts, filled by the table
// from its model class (plugin_sdk.hpp), and metadata_text, which writes them as the JSON text of plugin_abi.h.
// metadata_text is compiled once, in the SDK's library (plugins/sdk/src/metadata.cpp), so that a plugin's own
// translation units read no JSON (parameters.hpp says why).
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "nonsep/sdk/parameters.hpp"

namespace nonsep::sdk {

// A model's identity, as given to NONSEP_EXPORT_MODEL.
struct ModelIdentity {
  const char* name;
  const char* version;
  const char* description;
  const char* hamiltonian;
};

struct PluginFacts {
  ModelIdentity identity{};
  // "dimension": {"fixed": n} when fixed_dimension > 0, else {"parameter": ..., "max_dimension": ...}.
  std::size_t fixed_dimension = 0;
  const char* dimension_parameter = "";
  std::size_t max_dimension = 0;
  std::span<const Parameter> parameters;  // "parameters" (parameter_rules.hpp: parameters_metadata)
  bool general_form = false;              // "hamiltonian_form": "general" (a model given by H)
  std::vector<std::pair<const char*, bool>> capabilities;
  std::vector<std::pair<const char*, const char*>> derivatives;  // function, "analytic" or "automatic"
  std::string automatic_differentiation;
  bool has_kernels = false;  // "kernels": {"instruction_sets": [...]}
  std::span<const std::string_view> instruction_sets;
};

// The metadata JSON of plugin_abi.h for `facts`, with "thread_safe": true (plugin_sdk.hpp says why).
std::string metadata_text(const PluginFacts& facts);

}  // namespace nonsep::sdk
