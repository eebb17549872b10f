// The metadata checks of plugin_abi.h (plugin_internals.hpp), after the JSON has parsed.
#include <algorithm>
#include <set>
#include <string>

#include "nonsep/sdk/parameter_rules.hpp"
#include "plugin_internals.hpp"

namespace nonsep::host {

namespace fs = std::filesystem;
using nlohmann::json;

void check_metadata(const json& m, const nonsep_plugin_api& api, unsigned abi_version, const fs::path& path) {
  const std::string where = "the metadata of plugin " + quoted(path);
  auto fail = [&](const std::string& problem) { throw PluginError(where + " " + problem); };
  if (!m.is_object()) fail("must be a JSON object (found " + std::string(m.type_name()) + ")");
  for (const char* key : {"name", "version", "description", "hamiltonian"})
    if (!m.contains(key) || !m[key].is_string()) fail("lacks the string \"" + std::string(key) + "\"");
  const std::string name = m["name"].get<std::string>();
  if (name != path.stem().string())
    fail("declares the name '" + name + "' but the file is named " + path.filename().string() +
         "; a plugin's file must be <name>.so (expected '" + path.stem().string() + "', found '" + name + "')");

  if (!m.contains("parameters") || !m["parameters"].is_array()) fail("lacks the array \"parameters\"");
  std::set<std::string> parameter_names;
  for (const json& p : m["parameters"]) {
    if (!p.is_object() || !p.contains("name") || !p["name"].is_string())
      fail("has a parameter without a string \"name\"");
    const std::string parameter = p["name"].get<std::string>();
    if (!parameter_names.insert(parameter).second) fail("declares parameter '" + parameter + "' twice");
    const std::string type = p.value("type", json()).is_string() ? p["type"].get<std::string>() : "";
    if (type != "integer" && type != "number" && type != "boolean")
      fail("gives parameter '" + parameter + "' the type " + p.value("type", json()).dump() +
           " (expected \"integer\", \"number\" or \"boolean\")");
    if (!p.contains("default")) fail("gives parameter '" + parameter + "' no default");
    for (const char* bound : {"minimum", "maximum"})
      if (p.contains(bound) && !p[bound].is_number())
        fail("gives parameter '" + parameter + "' a non-numeric " + bound);
    for (const char* text : {"unit", "description"})
      if (p.contains(text) && !p[text].is_string()) fail("gives parameter '" + parameter + "' a non-string " + text);
    const auto bound = [&](const char* key) {
      return p.contains(key) ? std::optional<double>(p[key].get<double>()) : std::nullopt;
    };
    const std::string problem =
        sdk::check_parameter_value(parameter, type, bound("minimum"), bound("maximum"), p["default"]);
    if (!problem.empty()) fail("has an invalid default: " + problem);
  }

  if (!m.contains("dimension") || !m["dimension"].is_object()) fail("lacks the object \"dimension\"");
  const json& dimension = m["dimension"];
  if (dimension.contains("fixed")) {
    if (!dimension["fixed"].is_number_unsigned() || dimension["fixed"].get<std::uint64_t>() == 0)
      fail("gives \"dimension\": {\"fixed\": ...} a value that is not a positive integer (found " +
           dimension["fixed"].dump() + ")");
  } else if (dimension.contains("parameter")) {
    const json& parameter = dimension["parameter"];
    const auto& parameters = m["parameters"];
    const bool declared = parameter.is_string() &&
                          std::any_of(parameters.begin(), parameters.end(),
                                      [&](const json& p) { return p["name"] == parameter && p["type"] == "integer"; });
    if (!declared)
      fail("sets the dimension by parameter " + parameter.dump() + ", which is not a declared integer parameter");
  } else {
    fail("gives \"dimension\" neither \"fixed\" nor \"parameter\"");
  }

  if (!m.contains("thread_safe") || !m["thread_safe"].is_boolean())
    fail(
        "lacks the boolean \"thread_safe\" (required since plugin ABI version 3; true when distinct instances "
        "share no mutable state, false to be run as one instance on one thread" +
        (m.contains("thread_safe") ? "; found " + m["thread_safe"].dump() : std::string()) + ")");

  // The kind of model (version 6): its required functions, and no entry of the other kind.
  const json form = m.value("hamiltonian_form", json("product"));
  if (form != "product" && form != "general")
    fail("gives \"hamiltonian_form\" " + form.dump() + " (expected \"product\" or \"general\")");
  const bool general = form == "general";
  if (general && abi_version < 6)
    fail("says \"hamiltonian_form\": \"general\", which needs plugin ABI version 6 (found version " +
         std::to_string(abi_version) + ")");
  const std::pair<const char*, bool> required[] = {{"grad_T", api.grad_T != nullptr && !general},
                                                   {"grad_V", api.grad_V != nullptr && !general},
                                                   {"value_H", api.value_H != nullptr && general},
                                                   {"grad_H", api.grad_H != nullptr && general}};
  for (std::size_t i = general ? 2 : 0, end = i + 2; i < end; ++i)
    if (!required[i].second)
      throw PluginError("plugin " + quoted(path) + " lacks the required function " + required[i].first +
                        " (its table entry is null)" +
                        (general ? std::string(", which a model given by H (\"hamiltonian_form\": \"general\") needs")
                                 : std::string()));
  if (general) {
    const std::pair<const char*, bool> product_entries[] = {{"grad_T", api.grad_T != nullptr},
                                                            {"grad_V", api.grad_V != nullptr},
                                                            {"value_T", api.value_T != nullptr},
                                                            {"value_V", api.value_V != nullptr},
                                                            {"hessian_T", api.hessian_T != nullptr},
                                                            {"hessian_V", api.hessian_V != nullptr},
                                                            {"d3T", api.d3T != nullptr},
                                                            {"d3V", api.d3V != nullptr},
                                                            {"grad_K", api.grad_K != nullptr},
                                                            {"grad_U", api.grad_U != nullptr},
                                                            {"hvp_T", api.hvp_T != nullptr},
                                                            {"hvp_V", api.hvp_V != nullptr},
                                                            {"chin_steps", api.chin_steps != nullptr},
                                                            {"energy_TTV", api.energy_TTV != nullptr},
                                                            {"energy_VVT", api.energy_VVT != nullptr}};
    for (const auto& [entry, present] : product_entries)
      if (present)
        fail("says \"hamiltonian_form\": \"general\" but the table's " + std::string(entry) +
             " pointer is set (a model given by H has no T, V, K, U or kernels: leave them null)");
  } else if (api.value_H != nullptr || api.grad_H != nullptr) {
    fail("has value_H or grad_H in its table, which only a model given by H has (\"hamiltonian_form\": \"general\")");
  }

  if (!m.contains("capabilities") || !m["capabilities"].is_object()) fail("lacks the object \"capabilities\"");
  const std::pair<const char*, bool> present[] = {{"value_T", api.value_T != nullptr},
                                                  {"value_V", api.value_V != nullptr},
                                                  {"hessian_T", api.hessian_T != nullptr},
                                                  {"hessian_V", api.hessian_V != nullptr},
                                                  {"d3T", api.d3T != nullptr},
                                                  {"d3V", api.d3V != nullptr},
                                                  {"grad_K", api.grad_K != nullptr},
                                                  {"grad_U", api.grad_U != nullptr},
                                                  {"value_K", api.value_K != nullptr},
                                                  {"value_U", api.value_U != nullptr},
                                                  {"hessian_K", api.hessian_K != nullptr},
                                                  {"hessian_U", api.hessian_U != nullptr},
                                                  {"hvp_T", api.hvp_T != nullptr},
                                                  {"hvp_V", api.hvp_V != nullptr},
                                                  {"hvp_K", api.hvp_K != nullptr},
                                                  {"hvp_U", api.hvp_U != nullptr},
                                                  {"chin_steps", api.chin_steps != nullptr},
                                                  {"energy_TTV", api.energy_TTV != nullptr},
                                                  {"energy_VVT", api.energy_VVT != nullptr},
                                                  {"hvp_H", api.hvp_H != nullptr},
                                                  {"chin_tangent_steps", api.chin_tangent_steps != nullptr},
                                                  {"value_H", api.value_H != nullptr},
                                                  {"grad_H", api.grad_H != nullptr},
                                                  {"gauss_steps", api.gauss_steps != nullptr}};
  for (const auto& [capability, in_table] : present) {
    const json claimed = m["capabilities"].value(capability, json(false));
    if (!claimed.is_boolean()) fail("gives capability \"" + std::string(capability) + "\" a non-boolean value");
    if (claimed.get<bool>() != in_table)
      fail("says capability \"" + std::string(capability) + "\" is " + (claimed.get<bool>() ? "true" : "false") +
           " but the table's " + capability + " pointer is " + (in_table ? "set" : "null"));
  }
  // A part's value, Hessian and Hessian-vector product describe a part that its gradient makes.
  struct Part {
    const char* name;
    bool gradient, others;
  };
  const Part parts[] = {{"K", api.grad_K != nullptr, api.value_K || api.hessian_K || api.hvp_K},
                        {"U", api.grad_U != nullptr, api.value_U || api.hessian_U || api.hvp_U}};
  for (const Part& part : parts)
    if (part.others && !part.gradient)
      fail("gives the value, Hessian or Hessian-vector product of " + std::string(part.name) + " but not grad_" +
           part.name + " (a separable part is made by its gradient)");
  // The energy of H = T_i V_ij T_j + K + U needs the values of the parts the plugin has.
  const Part values[] = {{"K", api.grad_K != nullptr, api.value_K != nullptr},
                         {"U", api.grad_U != nullptr, api.value_U != nullptr}};
  for (const Part& part : values)
    if (part.gradient && !part.others)
      fail("gives grad_" + std::string(part.name) + " but not value_" + part.name +
           ": the energy of H = T_i V_ij T_j + K + U needs " + part.name + " itself");

  // "kernels": {"instruction_sets": ["x86-64", ...]}, exactly when the table has chin_steps; in version 4 with the
  // kernel version "version": K, which version 5 says by abi_version.
  if (api.chin_tangent_steps != nullptr && api.chin_steps == nullptr)
    fail("has chin_tangent_steps without chin_steps (the tangent kernel uses chin_steps' instruction sets)");
  if (m.contains("kernels") != (api.chin_steps != nullptr))
    fail(api.chin_steps != nullptr ? "lacks the object \"kernels\" that its chin_steps needs"
                                   : "has \"kernels\" but the table's chin_steps pointer is null");
  if (api.chin_steps != nullptr) {
    const json& kernels = m["kernels"];
    if (!kernels.is_object()) fail("gives \"kernels\" that is not an object (found " + kernels.dump() + ")");
    if (abi_version == 4 && (!kernels.contains("version") || !kernels["version"].is_number_unsigned()))
      fail("gives \"kernels\" no unsigned integer \"version\" (required in plugin ABI version 4)");
    if (abi_version != 4 && kernels.contains("version"))
      fail("gives \"kernels\" a \"version\", which plugin ABI version " + std::to_string(abi_version) +
           " says by abi_version alone (remove it)");
    const json sets = kernels.value("instruction_sets", json());
    if (!sets.is_array() || sets.empty() ||
        std::any_of(sets.begin(), sets.end(), [](const json& s) { return !s.is_string(); }))
      fail("gives \"kernels\" no non-empty array of strings \"instruction_sets\" (found " + sets.dump() + ")");
  }
}

}  // namespace nonsep::host
