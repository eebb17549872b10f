// metadata_text (nonsep/sdk/metadata.hpp): a table's facts as the metadata JSON of plugin_abi.h.
#include "nonsep/sdk/metadata.hpp"

#include "nonsep/sdk/parameter_rules.hpp"

namespace nonsep::sdk {

std::string metadata_text(const PluginFacts& facts) {
  nlohmann::json dimension;
  if (facts.fixed_dimension > 0)
    dimension = {{"fixed", facts.fixed_dimension}};
  else
    dimension = {{"parameter", facts.dimension_parameter}, {"max_dimension", facts.max_dimension}};
  nlohmann::json capabilities = nlohmann::json::object(), derivatives = nlohmann::json::object();
  for (const auto& [function, present] : facts.capabilities) capabilities[function] = present;
  for (const auto& [function, kind] : facts.derivatives) derivatives[function] = kind;
  nlohmann::json metadata = {{"name", facts.identity.name},
                             {"version", facts.identity.version},
                             {"description", facts.identity.description},
                             {"hamiltonian", facts.identity.hamiltonian},
                             {"dimension", dimension},
                             {"parameters", parameters_metadata(facts.parameters)},
                             {"thread_safe", true},
                             {"capabilities", capabilities},
                             {"derivatives", derivatives},
                             {"automatic_differentiation", facts.automatic_differentiation}};
  if (facts.general_form) metadata["hamiltonian_form"] = "general";
  if (facts.has_kernels) {
    nlohmann::json sets = nlohmann::json::array();
    for (const std::string_view set : facts.instruction_sets) sets.push_back(std::string(set));
    metadata["kernels"] = {{"instruction_sets", sets}};
  }
  return metadata.dump();
}

}  // namespace nonsep::sdk
