// job_schema(): the key tables (job_keys.hpp) and the scheme catalogue written as a JSON Schema. One schema per
// ValueType; objects from their tables; the shapes of their own (ValueType::defined) under $defs.
#include "nonsep/host/job_schema.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "job_keys.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

using namespace job_reader;
using schema_json = nlohmann::ordered_json;

namespace {

schema_json ref(const std::string& definition) { return {{"$ref", "#/$defs/" + definition}}; }

schema_json described(schema_json schema, const std::string& description) {
  schema["description"] = description;
  return schema;
}

schema_json forms() {
  schema_json names = schema_json::array();
  for (const auto& form : hamiltonian_forms()) names.push_back(form.name);
  return names;
}

schema_json object_schema(const KeyTable& table, const std::string& description = "");
schema_json value_schema(const KeyRule& rule);

// A table's pairs of keys: exactly one of two (oneOf, one per object), not both (dependentSchemas), both or neither
// (dependentRequired).
void add_pairs(schema_json& schema, const std::vector<KeyPair>& pairs) {
  for (const KeyPair& pair : pairs) switch (pair.kind) {
      case KeyPair::Kind::exactly_one:
        if (schema.contains("oneOf")) throw std::logic_error("two exactly-one pairs in one key table");
        schema["oneOf"] = {{{"required", {pair.first}}}, {{"required", {pair.second}}}};
        break;
      case KeyPair::Kind::at_most_one:
        schema["dependentSchemas"][pair.second] = {{"not", {{"required", {pair.first}}}}};
        break;
      case KeyPair::Kind::together:
        schema["dependentRequired"][pair.first] = {pair.second};
        schema["dependentRequired"][pair.second] = {pair.first};
        break;
    }
}

// A list of numbers (number_list), under $defs.
schema_json list_schema(const NumberList& list) {
  schema_json schema = {{"type", "array"}, {"minItems", 1}, {"maxItems", list.max_items}};
  if (list.distinct) schema["uniqueItems"] = true;
  schema["items"] = value_schema(list.item);
  if (!list.description.empty()) schema["description"] = list.description;
  return schema;
}

schema_json value_schema(const KeyRule& rule) {
  schema_json schema;
  switch (rule.type) {
    case ValueType::object:
      if (rule.keys) return object_schema(rule.keys(), rule.description);
      schema = {{"type", "object"}};
      break;
    case ValueType::text:
      schema = {{"type", "string"}};
      break;
    case ValueType::string:
      schema = {{"type", "string"}, {"minLength", 1}};
      if (!rule.pattern.empty()) schema["pattern"] = rule.pattern;
      break;
    case ValueType::boolean:
      schema = {{"type", "boolean"}};
      break;
    case ValueType::choice:
      schema = {{"enum", rule.choices}};
      break;
    case ValueType::path:
      schema = {{"type", "string"}, {"minLength", 1}, {"pattern", "^[^\\u0000]*$"}};
      break;
    case ValueType::finite:
      schema = ref("finite");
      if (std::isfinite(rule.at_least)) schema["minimum"] = rule.at_least;
      if (std::isfinite(rule.at_most)) schema["maximum"] = rule.at_most;
      break;
    case ValueType::order:
      schema = ref("order");
      break;
    case ValueType::nonzero:
      schema = ref("nonzero");
      break;
    case ValueType::positive:
      schema = ref("finite");
      schema["exclusiveMinimum"] = 0;
      break;
    case ValueType::nonnegative:
      schema = ref("finite");
      schema["minimum"] = 0;
      break;
    case ValueType::integer:
      schema = {{"type", "integer"}, {"minimum", rule.minimum}, {"maximum", rule.maximum}};
      break;
    case ValueType::form:
      schema = {{"enum", forms()}};
      break;
    case ValueType::defined:
      schema = ref(rule.definition);
      break;
  }
  if (!rule.default_value.is_null()) schema["default"] = rule.default_value;
  if (!rule.description.empty()) schema["description"] = rule.description;
  return schema;
}

schema_json object_schema(const KeyTable& table, const std::string& description) {
  schema_json schema = {{"type", "object"}};
  if (!description.empty()) schema["description"] = description;
  schema["additionalProperties"] = false;
  if (const auto required = table.required(); !required.empty()) schema["required"] = required;
  schema_json properties = schema_json::object();
  for (const auto& rule : table.rules) properties[rule.name] = value_schema(rule);
  schema["properties"] = std::move(properties);
  add_pairs(schema, table.pairs);
  return schema;
}

double number_from_text(const std::string& text) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size())
    throw std::logic_error("catalogue default '" + text + "' is not a number");
  return value;
}

schema_json option_schema(const ParameterDescription& parameter, const Scheme& scheme) {
  schema_json schema;
  if (parameter.kind == ParameterDescription::Kind::Order) {
    schema = ref("order");
    schema_json orders = schema_json::array();
    for (const Fraction& order : scheme.orders()) orders.push_back(order.to_string());
    schema["examples"] = std::move(orders);
    if (!parameter.default_text.empty()) schema["default"] = parameter.default_text;
  } else if (parameter.integer) {
    schema = {{"type", "integer"}};
    if (std::isfinite(parameter.minimum)) schema["minimum"] = static_cast<std::int64_t>(parameter.minimum);
    if (std::isfinite(parameter.maximum)) schema["maximum"] = static_cast<std::int64_t>(parameter.maximum);
    if (!parameter.default_text.empty())
      schema["default"] = static_cast<std::int64_t>(number_from_text(parameter.default_text));
  } else {
    schema = ref(parameter.nonzero ? "nonzero" : "finite");
    if (std::isfinite(parameter.minimum))
      schema[parameter.minimum_exclusive ? "exclusiveMinimum" : "minimum"] = parameter.minimum;
    if (std::isfinite(parameter.maximum)) schema["maximum"] = parameter.maximum;
    if (!parameter.default_text.empty()) schema["default"] = number_from_text(parameter.default_text);
  }
  schema["description"] = parameter.description;
  return schema;
}

// An integrator object: "scheme" and, per scheme, exactly that scheme's options (and `extra`'s keys).
schema_json integrator_schema(const KeyTable* extra, const std::string& description) {
  schema_json names = schema_json::array();
  schema_json branches = schema_json::array();
  for (const auto& scheme : scheme_catalogue()) {
    names.push_back(scheme.name);
    schema_json properties = {{"scheme", true}};
    for (const auto& parameter : scheme.parameters) properties[parameter.name] = option_schema(parameter, scheme);
    if (extra)
      for (const auto& rule : extra->rules) properties[rule.name] = value_schema(rule);
    schema_json required = schema_json::array();
    for (const auto& parameter : scheme.parameters)
      if (parameter.default_text.empty()) required.push_back(parameter.name);
    schema_json then = {{"description", "[family " + scheme.family + "] " + scheme.method + ", " + scheme.equations +
                                            ". " + scheme.summary},
                        {"properties", std::move(properties)},
                        {"additionalProperties", false}};
    if (!required.empty()) then["required"] = std::move(required);
    branches.push_back({{"if", {{"properties", {{"scheme", {{"const", scheme.name}}}}}}}, {"then", std::move(then)}});
  }
  if (!extra) {  // a run's integrator may also be chosen: {"scheme": "auto", ...}
    names.push_back("auto");
    schema_json properties = {{"scheme", true}};
    for (const auto& rule : auto_integrator_keys().rules) properties[rule.name] = value_schema(rule);
    branches.push_back(
        {{"if", {{"properties", {{"scheme", {{"const", "auto"}}}}}}},
         {"then",
          {{"description",
            "A scheme and step chosen by pilot runs for the accuracy asked for (docs/user-guide.md, \"Scheme "
            "auto\"): among the schemes the plugin allows, the one that meets the tolerance at the least "
            "predicted cost."},
           {"properties", std::move(properties)},
           {"additionalProperties", false},
           {"required", auto_integrator_keys().required()}}}});
  }
  schema_json schema = {{"type", "object"}, {"description", description}, {"required", {"scheme"}}};
  schema["properties"] = {
      {"scheme",
       {{"enum", std::move(names)},
        {"description",
         "The scheme, by its name in the core's catalogue (`nonsep --help` lists each with its family and options); "
         "the other keys are that scheme's options."}}}};
  if (extra) add_pairs(schema, extra->pairs);
  schema["allOf"] = std::move(branches);
  return schema;
}

schema_json definitions() {
  const double largest = std::numeric_limits<double>::max();
  schema_json defs;
  defs["finite"] = {{"type", "number"}, {"minimum", -largest}, {"maximum", largest}};
  defs["nonzero"] = ref("finite");
  defs["nonzero"]["not"] = {{"const", 0}};
  defs["order"] = {
      {"description", "An exact fraction as a string (\"4/3\") or a positive integer; the orders of the family are " +
                          chin_orders_text() + ", and each scheme has those up to its own highest."},
      {"oneOf",
       {{{"type", "string"}, {"pattern", "^[ \\t]*\\+?[0-9]+[ \\t]*(/[ \\t]*[0-9]+[ \\t]*)?$"}},
        {{"type", "integer"}, {"minimum", 1}}}}};
  defs["integrator"] = integrator_schema(nullptr,
                                         "The scheme (nonsep::scheme_catalogue(), `nonsep --help`) and "
                                         "its options; a missing option takes its default.");
  defs["study_integrators"] = {{"type", "array"}, {"minItems", 1}, {"items", ref("study_integrator")}};
  defs["study_integrator"] = integrator_schema(&study_integrator_keys(),
                                               "An integrator as /integrator of a run, with an optional label and "
                                               "its own steps or dt (which override the study's).");
  defs["run_time"] = object_schema(run_time_keys());
  defs["study_time"] = object_schema(study_time_keys());
  for (const NumberList& list : number_lists()) defs[list.definition] = list_schema(list);
  defs["formula"] = formula::formula_schema();
  defs["parameters"] = {
      {"type", "object"},
      {"additionalProperties",
       {{"oneOf",
         {{{"type", {"number", "boolean"}}},
          {{"type", "array"},
           {"minItems", 1},
           {"maxItems", max_initial_states},
           {"items", {{"type", {"number", "boolean"}}}}},
          object_schema(range_axis_keys(),
                        "A sweep over count evenly spaced values from `from` to `to`, both included (count 1: just "
                        "`from`); between them the doubles nearest the decimal values (0 to 0.3 in 16 values: 0.06)."),
          object_schema(values_axis_keys(), "A sweep over the values listed.")}},
        {"description",
         "A parameter of the plugin by its name (`nonsep inspect PLUGIN` lists them): checked against the plugin's "
         "metadata (known name, type, minimum and maximum); an integer parameter takes an integral number of "
         "magnitude at most 2^53. Several values (an array, {\"values\": [...]} or {\"from\", \"to\", "
         "\"count\"}) make a sweep: the run takes every parameter set of the product of the swept parameters with "
         "every initial state (docs/dynamics.md). Every set must give the model the same dimension: a sweep of a "
         "parameter that sets it (lattice_chain's sites) is refused."}}}};
  defs["state"] = object_schema(state_keys());
  defs["initial"] = {{"oneOf",
                      {ref("state"),
                       {{"type", "array"}, {"minItems", 1}, {"maxItems", max_initial_states}, {"items", ref("state")}},
                       object_schema(initial_grid_keys()),
                       object_schema(initial_file_keys())}}};
  defs["axes"] = {{"type", "array"}, {"minItems", 1}, {"items", ref("axis")}};
  schema_json fixed = ref("finite");
  fixed["description"] = "A fixed value.";
  defs["axis"] = {{"oneOf",
                   {std::move(fixed),
                    object_schema(range_axis_keys(),
                                  "count evenly spaced values from `from` to `to`, both included (count 1: "
                                  "just `from`); between them the doubles nearest the decimal values."),
                    object_schema(values_axis_keys(), "The values listed.")}}};
  return defs;
}

}  // namespace

schema_json job_schema() {
  const KeyTable& keys = document_keys();
  schema_json schema = {
      {"$schema", "https://json-schema.org/draft/2020-12/schema"},
      {"$id", "https://github.com/nonsep/nonsep/schemas/job.schema.json"},
      {"title", "nonsep job file"},
      {"description",
       "A run of `nonsep run JOB.json`: a model plugin, the Hamiltonian form, a Chin integrator, initial states, a "
       "time grid and outputs; or a convergence study (`study`): several integrators at several step sizes, from "
       "one initial state to one end time. Documented key by key in docs/job-file.md (generated from this schema) "
       "and explained in docs/user-guide.md. Generated by `nonsep schema` from the job reader's key tables and the "
       "core's scheme catalogue; do not edit. The host checks more than this schema can express: the plugin's "
       "parameters and dimension, which orders a scheme has, that t_end and dt have the same sign, that q and p have "
       "the same length, duplicate keys."}};
  schema.update(object_schema(keys));
  // A study refuses the run-only keys and has one state and its own /time; a run needs /integrator.
  schema_json run_only = schema_json::array();
  for (const auto& rule : keys.rules)
    if (rule.run_only) run_only.push_back({{"required", {rule.name}}});
  schema["allOf"] = {
      {{"if", {{"required", {"study"}}}},
       {"then",
        {{"not", {{"anyOf", std::move(run_only)}}},
         {"properties",
          {{"initial", described(ref("state"), "A study starts from one state.")},
           {"time", described(ref("study_time"), "A study's time: t_end only.")}}}}},
       {"else",
        {{"required", {"integrator"}},
         {"properties", {{"time", described(ref("run_time"), "A run's time grid: dt, and t_end or steps.")}}}}}}};
  schema["$defs"] = definitions();
  return schema;
}

}  // namespace nonsep::host
