#include "nonsep/host/json/parameter_check.hpp"

#include "nonsep/host/number_format.hpp"
#include "nonsep/sdk/parameter_rules.hpp"

namespace nonsep::host::job_reader {

using nlohmann::json;

void check_parameter_value(Checker& check, const PluginParameter& parameter, const json& value, const std::string& path,
                           const std::string& found) {
  const auto fault = sdk::parameter_fault(parameter.type, parameter.minimum, parameter.maximum, value);
  if (fault == sdk::ParameterFault::none) return;
  std::string range;
  if (parameter.minimum) range += " >= " + format_number(*parameter.minimum);
  if (parameter.minimum && parameter.maximum) range += " and";
  if (parameter.maximum) range += " <= " + format_number(*parameter.maximum);
  if (!parameter.unit.empty()) range += " (" + parameter.unit + ")";
  const std::string type_text = parameter.type == "boolean"   ? "true or false"
                                : parameter.type == "integer" ? "an integer" + range
                                                              : "a finite number" + range;
  switch (fault) {
    case sdk::ParameterFault::none:
      break;
    case sdk::ParameterFault::wrong_type:
      check.issue(path, found, type_text + ": " + parameter.description);
      break;
    case sdk::ParameterFault::below_minimum:
    case sdk::ParameterFault::above_maximum:
      check.issue(path, found, "a value" + range + ": " + parameter.description);
      break;
  }
}

}  // namespace nonsep::host::job_reader
