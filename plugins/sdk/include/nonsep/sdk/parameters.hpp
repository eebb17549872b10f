#pragma once
// Model parameters: the static table a model declares, and the checked values it is constructed from.
//
// A model lists its parameters as
//   static constexpr nonsep::sdk::Parameter parameters[] = {
//       {.name = "lambda", .type = nonsep::sdk::ParameterType::number, .default_value = 1.0,
//        .minimum = -10.0, .maximum = 10.0, .description = "Henon-Heiles coupling"}};
// and receives a ParameterValues in its constructor. The same table produces the "parameters" array of the
// plugin metadata (plugin_abi.h), so the host can validate and document parameters without creating a model.
//
// Rules: the parameters are a JSON object; every key must be in the table; each value must pass
// parameter_fault, the one rule for a value that the SDK, the host's plugin loader and its job reader all apply:
//   "integer"  a JSON number with an integral value (2 or 2.0, as JSON Schema counts integers) of magnitude at
//              most 2^53, so that the double a model reads it through (ParameterValues::integer) holds it exactly;
//   "number"   a finite JSON number (a text such as 1e999 reads as infinity);
//   "boolean"  true or false;
// minimum and maximum are inclusive. Missing keys take their defaults. Every refusal throws InvalidParameter with a
// message that names the parameter and shows the offending value.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace nonsep::sdk {

enum class ParameterType { integer, number, boolean };

inline const char* to_string(ParameterType type) {
  switch (type) {
    case ParameterType::integer:
      return "integer";
    case ParameterType::number:
      return "number";
    case ParameterType::boolean:
      return "boolean";
  }
  return "?";
}

// One row of a model's parameter table. For a boolean, default_value is 0 or 1 and there is no range.
struct Parameter {
  const char* name = "";
  ParameterType type = ParameterType::number;
  double default_value = 0.0;
  std::optional<double> minimum{};  // inclusive; absent = unbounded
  std::optional<double> maximum{};  // inclusive; absent = unbounded
  const char* unit = "";            // "" when the parameter has no unit
  const char* description = "";
};

// A parameter was refused. `parameter()` is its name ("" when the whole parameter text was refused).
class InvalidParameter : public std::invalid_argument {
 public:
  InvalidParameter(std::string parameter, const std::string& message)
      : std::invalid_argument(message), parameter_(std::move(parameter)) {}
  const std::string& parameter() const { return parameter_; }

 private:
  std::string parameter_;
};

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
// by the rules at the top of this file.
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

// The parameters in effect for one model instance: every table entry, given or defaulted, already checked.
class ParameterValues {
 public:
  ParameterValues() : values_(nlohmann::json::object()) {}
  explicit ParameterValues(nlohmann::json checked_object) : values_(std::move(checked_object)) {}

  // The value of a declared parameter. Asking for a name the table does not declare, or with the wrong type,
  // is a bug in the model and throws std::logic_error.
  double number(std::string_view name) const { return at(name, "number").get<double>(); }
  std::int64_t integer(std::string_view name) const {
    return static_cast<std::int64_t>(at(name, "integer").get<double>());
  }
  bool boolean(std::string_view name) const { return at(name, "boolean").get<bool>(); }
  const nlohmann::json& json() const { return values_; }

 private:
  const nlohmann::json& at(std::string_view name, const char* type) const {
    const auto it = values_.find(std::string(name));
    if (it == values_.end())
      throw std::logic_error("the model asked for parameter '" + std::string(name) + "', which it does not declare");
    if (type == std::string_view("boolean") ? !it->is_boolean() : !it->is_number())
      throw std::logic_error("the model asked for parameter '" + std::string(name) + "' as a " + type);
    return *it;
  }
  nlohmann::json values_;
};

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

// Parses and checks parameters given as JSON text against a table (an empty text means "{}").
// Throws InvalidParameter naming the parameter; see the rules at the top of this file.
inline ParameterValues parse_parameters(std::span<const Parameter> table, std::string_view json_text) {
  nlohmann::json given;
  try {
    given = json_text.empty() ? nlohmann::json::object() : nlohmann::json::parse(json_text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidParameter("", std::string("the parameters are not valid JSON: ") + e.what());
  }
  if (!given.is_object())
    throw InvalidParameter("", "the parameters must be a JSON object such as {\"name\": value} (found " +
                                   std::string(given.type_name()) + ")");
  return ParameterValues(checked_parameters(
      table, given, [](const Parameter& p) { return to_string(p.type); }, default_as_json));
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
