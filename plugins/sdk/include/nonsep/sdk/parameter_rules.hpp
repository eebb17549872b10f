#pragma once
// The rules for parameter values (parameters.hpp, at the top), over JSON: the one walk that the SDK's library
// (parse_parameters, inside a plugin), the host's plugin loader (over the rows of a plugin's metadata) and its job
// reader all apply, and the "parameters" array of a plugin's metadata. Not for a plugin's own sources: it includes
// nlohmann/json.hpp, which the SDK compiles once, in its library (plugins/sdk/src).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "nonsep/sdk/parameters.hpp"

namespace nonsep::sdk {

// Shortest text that reads back as the same double; integral values without a decimal point.
inline std::string format_number(double x) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}

// The default of a table row as JSON of the row's type.
inline nlohmann::json default_as_json(const Parameter& p) {
  switch (p.type) {
    case ParameterType::integer:
      return static_cast<std::int64_t>(p.default_value);
    case ParameterType::boolean:
      return p.default_value != 0.0;
    case ParameterType::number:
      break;
  }
  return p.default_value;
}

enum class ParameterFault { none, wrong_type, below_minimum, above_maximum };

// A JSON number with an integral value of magnitude at most 2^53.
inline bool is_exact_integer(const nlohmann::json& value) {
  constexpr std::int64_t limit = std::int64_t{1} << 53;
  if (value.is_number_unsigned()) return value.get<std::uint64_t>() <= static_cast<std::uint64_t>(limit);
  if (value.is_number_integer()) return value.get<std::int64_t>() >= -limit && value.get<std::int64_t>() <= limit;
  if (!value.is_number_float()) return false;
  const double x = value.get<double>();
  return std::trunc(x) == x && std::abs(x) <= 0x1p53;
}

// What is wrong with one value of a parameter of `type` ("integer", "number" or "boolean") with inclusive bounds,
// by the rules at the top of parameters.hpp.
inline ParameterFault parameter_fault(std::string_view type, std::optional<double> minimum,
                                      std::optional<double> maximum, const nlohmann::json& value) {
  if (type == "boolean") return value.is_boolean() ? ParameterFault::none : ParameterFault::wrong_type;
  if (!value.is_number()) return ParameterFault::wrong_type;
  const double x = value.get<double>();
  if (!std::isfinite(x)) return ParameterFault::wrong_type;
  if (type == "integer" && !is_exact_integer(value)) return ParameterFault::wrong_type;
  if (minimum && x < *minimum) return ParameterFault::below_minimum;
  if (maximum && x > *maximum) return ParameterFault::above_maximum;
  return ParameterFault::none;
}

// parameter_fault as a message: "" when the value is acceptable, otherwise the complete message, e.g.
// "parameter 'dimension' = 100 is above its maximum 16".
inline std::string check_parameter_value(std::string_view name, std::string_view type, std::optional<double> minimum,
                                         std::optional<double> maximum, const nlohmann::json& value) {
  const std::string quoted = "parameter '" + std::string(name) + "'";
  switch (parameter_fault(type, minimum, maximum, value)) {
    case ParameterFault::none:
      return "";
    case ParameterFault::wrong_type:
      return quoted + " must be " +
             (type == "boolean"   ? "true or false"
              : type == "integer" ? "an integer"
                                  : "a number") +
             " (found " + value.dump() + ")";
    case ParameterFault::below_minimum:
      return quoted + " = " + value.dump() + " is below its minimum " + format_number(*minimum);
    case ParameterFault::above_maximum:
      return quoted + " = " + value.dump() + " is above its maximum " + format_number(*maximum);
  }
  return "";
}

// The parameter object `given` checked against a model's declared rows and completed with their defaults: the one
// walk of the rules above, shared by the SDK (parse_parameters, inside a plugin) and the host's plugin loader (over
// the rows of the plugin's metadata). A row has name, minimum and maximum; type_of(row) gives its type's name,
// default_of(row) its default as JSON. Throws InvalidParameter naming the first key refused.
template <class Row, class TypeOf, class DefaultOf>
nlohmann::json checked_parameters(std::span<const Row> rows, const nlohmann::json& given, TypeOf type_of,
                                  DefaultOf default_of) {
  nlohmann::json checked = nlohmann::json::object();
  for (const auto& [key, value] : given.items()) {
    const auto row = std::find_if(rows.begin(), rows.end(), [&name = key](const Row& p) { return name == p.name; });
    if (row == rows.end()) {
      std::string known;
      for (const Row& p : rows) known += (known.empty() ? "" : ", ") + std::string(p.name);
      throw InvalidParameter(key, "unknown parameter '" + key + "' (" +
                                      (known.empty() ? "this model has no parameters" : "known parameters: " + known) +
                                      ")");
    }
    const std::string problem = check_parameter_value(key, type_of(*row), row->minimum, row->maximum, value);
    if (!problem.empty()) throw InvalidParameter(key, problem);
    checked[key] = value;
  }
  for (const Row& p : rows)
    if (!checked.contains(p.name)) checked[p.name] = default_of(p);
  return checked;
}

// The "parameters" array of the plugin metadata for a table.
inline nlohmann::json parameters_metadata(std::span<const Parameter> table) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& p : table) {
    nlohmann::json row = {
        {"name", p.name}, {"type", to_string(p.type)}, {"default", default_as_json(p)}, {"description", p.description}};
    if (p.minimum) row["minimum"] = *p.minimum;
    if (p.maximum) row["maximum"] = *p.maximum;
    if (*p.unit) row["unit"] = p.unit;
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace nonsep::sdk
