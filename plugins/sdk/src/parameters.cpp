// parse_parameters (nonsep/sdk/parameters.hpp): the rules of parameter_rules.hpp over the JSON text a plugin's
// create() receives.
#include "nonsep/sdk/parameters.hpp"

#include "nonsep/sdk/parameter_rules.hpp"

namespace nonsep::sdk {

ParameterValues parse_parameters(std::span<const Parameter> table, std::string_view json_text) {
  nlohmann::json given;
  try {
    given = json_text.empty() ? nlohmann::json::object() : nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidParameter("", std::string("the parameters are not valid JSON: ") + e.what());
  }
  if (!given.is_object())
    throw InvalidParameter("", "the parameters must be a JSON object such as {\"name\": value} (found " +
                                   std::string(given.type_name()) + ")");
  const nlohmann::json checked = checked_parameters(
      table, given, [](const Parameter& p) { return to_string(p.type); }, default_as_json);
  std::vector<ParameterValues::Entry> entries;
  entries.reserve(table.size());
  for (const Parameter& p : table) {
    const nlohmann::json& value = checked.at(p.name);
    entries.push_back({p.name, p.type, value.is_boolean() ? (value.get<bool>() ? 1.0 : 0.0) : value.get<double>()});
  }
  return ParameterValues(std::move(entries));
}

}  // namespace nonsep::sdk
