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
//
// This header reads no JSON: parse_parameters is compiled once, in the SDK's library (plugins/sdk/src), and the rules
// themselves are nonsep/sdk/parameter_rules.hpp, which the library and the host's job reader and plugin loader
// include. A plugin's own translation units then never parse or instantiate nlohmann::json (about 7 s of compile
// time of every plugin: docs/writing-models.md, "How long a plugin takes to build").
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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

// The parameters in effect for one model instance: every table entry, given or defaulted, already checked.
class ParameterValues {
 public:
  // One checked value: an integer (exact, |value| <= 2^53) or a number as a double; a boolean as 0 or 1.
  struct Entry {
    std::string name;
    ParameterType type = ParameterType::number;
    double value = 0.0;
    bool operator==(const Entry&) const = default;
  };
  ParameterValues() = default;
  explicit ParameterValues(std::vector<Entry> checked) : entries_(std::move(checked)) {}

  // The value of a declared parameter. Asking for a name the table does not declare, or with the wrong type (a
  // boolean as a number, a number as a boolean), is a bug in the model and throws std::logic_error.
  double number(std::string_view name) const { return at(name, "number").value; }
  std::int64_t integer(std::string_view name) const { return static_cast<std::int64_t>(at(name, "integer").value); }
  bool boolean(std::string_view name) const { return at(name, "boolean").value != 0.0; }
  bool operator==(const ParameterValues&) const = default;

 private:
  const Entry& at(std::string_view name, const char* type) const {
    for (const Entry& entry : entries_) {
      if (entry.name != name) continue;
      if ((type == std::string_view("boolean")) != (entry.type == ParameterType::boolean))
        throw std::logic_error("the model asked for parameter '" + std::string(name) + "' as a " + type);
      return entry;
    }
    throw std::logic_error("the model asked for parameter '" + std::string(name) + "', which it does not declare");
  }
  std::vector<Entry> entries_;
};

// Parses and checks parameters given as JSON text against a table (an empty text means "{}"), by the rules of
// parameter_rules.hpp. Throws InvalidParameter naming the parameter; see the rules at the top of this file.
// Compiled in the SDK's library (plugins/sdk/src/parameters.cpp).
ParameterValues parse_parameters(std::span<const Parameter> table, std::string_view json_text);

}  // namespace nonsep::sdk
