// Parameter handling of the SDK (inside create()): each refusal names the parameter and shows the value.
#include <doctest/doctest.h>

#include <string>

#include "nonsep/sdk/parameter_rules.hpp"

namespace test_sdk_parameters {

using namespace nonsep::sdk;

namespace {

constexpr Parameter table[] = {
    {.name = "dimension", .type = ParameterType::integer, .default_value = 2, .minimum = 1, .maximum = 16},
    {.name = "lambda", .type = ParameterType::number, .default_value = 1.0, .unit = "1/length"},
    {.name = "symmetric", .type = ParameterType::boolean, .default_value = 1}};

std::string refusal(const std::string& text, std::string* parameter = nullptr) {
  try {
    parse_parameters(table, text);
  } catch (const InvalidParameter& e) {
    if (parameter) *parameter = e.parameter();
    return e.what();
  }
  return "(accepted)";
}

}  // namespace

TEST_CASE("missing parameters take their defaults, given ones their values") {
  const auto values = parse_parameters(table, R"({"lambda": -0.5})");
  CHECK(values.integer("dimension") == 2);
  CHECK(values.number("lambda") == -0.5);
  CHECK(values.boolean("symmetric"));
  CHECK(parse_parameters(table, "") == parse_parameters(table, "{}"));
  CHECK(parse_parameters(table, R"({"dimension": 3.0})").integer("dimension") == 3);
}

TEST_CASE("each kind of bad parameter gets its own message naming the parameter") {
  std::string parameter;
  CHECK(refusal(R"({"dimension": 17})", &parameter) == "parameter 'dimension' = 17 is above its maximum 16");
  CHECK(parameter == "dimension");
  CHECK(refusal(R"({"dimension": 0})") == "parameter 'dimension' = 0 is below its minimum 1");
  CHECK(refusal(R"({"dimension": 2.5})") == "parameter 'dimension' must be an integer (found 2.5)");
  CHECK(refusal(R"({"lambda": "big"})") == "parameter 'lambda' must be a number (found \"big\")");
  CHECK(refusal(R"({"symmetric": 1})") == "parameter 'symmetric' must be true or false (found 1)");
  CHECK(refusal(R"({"lamda": 2})", &parameter) ==
        "unknown parameter 'lamda' (known parameters: dimension, lambda, symmetric)");
  CHECK(parameter == "lamda");
  CHECK(refusal("[1, 2]") == "the parameters must be a JSON object such as {\"name\": value} (found array)");
  CHECK(refusal("{\"lambda\": }").rfind("the parameters are not valid JSON: ", 0) == 0);
}

TEST_CASE("the metadata rows carry type, default, range, unit and description") {
  const auto rows = parameters_metadata(table);
  REQUIRE(rows.size() == 3);
  CHECK(rows[0]["type"] == "integer");
  CHECK(rows[0]["default"] == 2);
  CHECK(rows[0]["maximum"] == 16.0);
  CHECK(rows[1]["unit"] == "1/length");
  CHECK_FALSE(rows[1].contains("minimum"));
  CHECK(rows[2]["default"] == true);
}

TEST_CASE("a model asking for an undeclared parameter is a bug, reported as such") {
  const auto values = parse_parameters(table, "{}");
  CHECK_THROWS_AS(values.number("lambda2"), std::logic_error);
  CHECK_THROWS_AS(values.boolean("lambda"), std::logic_error);
}

}  // namespace test_sdk_parameters
