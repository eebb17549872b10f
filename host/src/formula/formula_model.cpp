// Reading a formula model (formula_model.hpp) from a job's /model/formula or from a model file.
#include "nonsep/host/formula/formula_model.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "nonsep/host/json/checker.hpp"
#include "nonsep/host/json/parameter_check.hpp"
#include "nonsep/host/json/strict_json.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::formula {

namespace {

using job_reader::Checker;
using nlohmann::json;

constexpr std::size_t max_model_file_bytes = std::size_t{1} << 20;
const std::vector<std::string> formula_keys = {"name", "H", "T", "V", "dT", "dV", "K", "U", "parameters", "dimension"};
const std::vector<std::string> product_form_keys = {"T", "V", "dT", "dV", "K", "U"};

bool is_plugin_name(const std::string& name) {
  if (name.empty() || name.size() > 64 || !(name[0] == '_' || (name[0] >= 'a' && name[0] <= 'z'))) return false;
  return std::all_of(name.begin(), name.end(),
                     [](char c) { return c == '_' || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); });
}

std::string formula_of(const Symbols& symbols) {
  const std::string variables = symbols.variables == "q"   ? "q0, q1, ..."
                                : symbols.variables == "p" ? "p0, p1, ..."
                                                           : "q0, q1, ..., p0, p1, ...";
  return "a formula of " + variables + " (the formula grammar: docs/formula-models.md)";
}

// The formula `value` at `path`, parsed against its variable letter and the parameters; an issue quoting it on
// failure.
std::optional<Node> parse_at(Checker& check, const json& value, const std::string& path, const Symbols& symbols) {
  const std::string what = formula_of(symbols);
  if (!value.is_string()) {
    check.issue(path, job_reader::describe(value), what);
    return std::nullopt;
  }
  const std::string& text = value.get_ref<const std::string&>();
  auto result = parse_formula(text, symbols);
  if (const auto* error = std::get_if<FormulaError>(&result)) {
    check.issue(path,
                error->found + " at column " + std::to_string(error->column) + ":\n" +
                    point_at(text, error->column, "      ") + "\n   ",
                error->allowed);
    return std::nullopt;
  }
  return std::get<Node>(std::move(result));
}

// One of T, V, K and U.
std::optional<Node> read_term(Checker& check, const json& object, const std::string& pointer, const char* key,
                              const Symbols& symbols, bool required = true) {
  const json* value = check.member(object, pointer, key, required, formula_of(symbols));
  if (!value) return std::nullopt;
  return parse_at(check, *value, job_reader::child(pointer, key), symbols);
}

// "dT" or "dV": an array of formulas, one per component of the gradient; each parsed as read_term parses T or V.
std::optional<std::vector<Node>> read_gradient(Checker& check, const json& object, const std::string& pointer,
                                               const char* key, const Symbols& symbols) {
  const json* value = check.member(object, pointer, key, false, "");
  if (!value) return std::nullopt;
  const std::string path = job_reader::child(pointer, key);
  const std::string what = std::string("an array of 1 to ") + std::to_string(max_formula_dimension) + " formulas of " +
                           symbols.variables + "0, " + symbols.variables + "1, ..., component i the derivative by " +
                           symbols.variables + "i";
  if (!value->is_array() || value->empty() || value->size() > max_formula_dimension) {
    check.issue(path, job_reader::describe(*value), what);
    return std::nullopt;
  }
  std::vector<Node> components;
  for (std::size_t i = 0; i < value->size(); ++i)
    if (auto tree = parse_at(check, (*value)[i], job_reader::child(path, i), symbols))
      components.push_back(std::move(*tree));
  if (components.size() != value->size()) return std::nullopt;
  return components;
}

// "grad T = [a, b]": the canonical text of a function given by its gradient.
std::string gradient_text(const char* function, const std::vector<Node>& gradient) {
  std::string text;
  for (const Node& component : gradient) text += (text.empty() ? "" : ", ") + print(component);
  return std::string("grad ") + function + " = [" + text + "]";
}

// T or V, or its gradient dT or dV (exactly one of the two), into `tree` or `gradient`; false after an issue.
bool read_function(Checker& check, const json& object, const std::string& pointer, const char* key,
                   const Symbols& symbols, Node& tree, std::vector<Node>& gradient, std::string& text) {
  const std::string gradient_key = std::string("d") + key;
  const bool has_function = object.contains(key), has_gradient = object.contains(gradient_key);
  if (has_function && has_gradient) {
    check.issue(job_reader::child(pointer, gradient_key), std::string("both ") + key + " and " + gradient_key,
                std::string("one of them: ") + key + " or its gradient " + gradient_key);
    return false;
  }
  if (has_gradient) {
    auto components = read_gradient(check, object, pointer, gradient_key.c_str(), symbols);
    if (!components) return false;
    gradient = std::move(*components);
    text = gradient_text(key, gradient);
    return true;
  }
  auto function = read_term(check, object, pointer, key, symbols);
  if (!function) return false;
  tree = std::move(*function);
  text = print(tree);
  return true;
}

// H(q, p) of a model given by H; false after an issue (among them any key of the product form beside H).
bool read_hamiltonian(Checker& check, const json& object, const std::string& pointer, Symbols symbols,
                      FormulaModel& model) {
  bool alone = true;
  for (const auto& key : product_form_keys)
    if (object.contains(key)) {
      check.issue(job_reader::child(pointer, key), "both H and " + key,
                  "either H alone (a Hamiltonian H(q, p) of any shape) or T and V, with K and U optional (H in "
                  "product form, docs/formula-models.md)");
      alone = false;
    }
  symbols.variables = "qp";
  model.h_tree = read_term(check, object, pointer, "H", symbols);
  if (!model.h_tree || !alone) return false;
  model.H = print(*model.h_tree);
  model.dimension = std::max(dimension_used(*model.h_tree), std::size_t{1});
  return true;
}

// T (or dT), V (or dV), K and U of a model in product form; false after an issue.
bool read_product_form(Checker& check, const json& object, const std::string& pointer, Symbols symbols,
                       FormulaModel& model) {
  const std::size_t before = check.issue_count();
  symbols.variables = "p";
  const bool has_t = read_function(check, object, pointer, "T", symbols, model.t_tree, model.t_gradient, model.T);
  model.k_tree = read_term(check, object, pointer, "K", symbols, false);
  symbols.variables = "q";
  const bool has_v = read_function(check, object, pointer, "V", symbols, model.v_tree, model.v_gradient, model.V);
  model.u_tree = read_term(check, object, pointer, "U", symbols, false);
  if (!has_t || !has_v || check.issue_count() != before) return false;
  std::size_t used = std::max({dimension_used(model.t_tree), dimension_used(model.v_tree), std::size_t{1}});
  for (const auto* gradient : {&model.t_gradient, &model.v_gradient}) {
    used = std::max(used, gradient->size());
    for (const Node& component : *gradient) used = std::max(used, dimension_used(component));
  }
  if (model.k_tree) {
    model.K = print(*model.k_tree);
    used = std::max(used, dimension_used(*model.k_tree));
  }
  if (model.u_tree) {
    model.U = print(*model.u_tree);
    used = std::max(used, dimension_used(*model.u_tree));
  }
  model.dimension = used;
  return true;
}

// A formula's parameter as its plugin declares it.
PluginParameter as_declared(const FormulaParameter& parameter) {
  return {parameter.name,
          "number",
          parameter.value,
          parameter.minimum,
          parameter.maximum,
          "",
          formula_parameter_description};
}

// One parameter: its default, a number, or {"value": default, "min": ..., "max": ...} (either bound optional; the
// default within them). Nothing, with issues added, when anything is wrong.
std::optional<FormulaParameter> read_parameter(Checker& check, const std::string& name, const json& value,
                                               const std::string& path) {
  const std::string what =
      "the parameter's default, a finite number, or {\"value\": default, \"min\": ..., \"max\": ...} with its "
      "allowed range";
  FormulaParameter parameter;
  parameter.name = name;
  if (!value.is_object()) {
    const auto number = check.finite_number(value, path, what);
    if (!number) return std::nullopt;
    parameter.value = *number;
    return parameter;
  }
  const std::size_t before = check.issue_count();
  check.known_keys(value, path, {"value", "min", "max"});
  const auto number = [&](const char* key, bool required, const std::string& allowed) -> std::optional<double> {
    const json* member = check.member(value, path, key, required, allowed);
    return member ? check.finite_number(*member, job_reader::child(path, key), allowed) : std::nullopt;
  };
  const auto given = number("value", true, "the parameter's default, a finite number");
  parameter.minimum = number("min", false, "the smallest value allowed, a finite number");
  parameter.maximum = number("max", false, "the largest value allowed, a finite number");
  if (check.issue_count() != before || !given) return std::nullopt;
  parameter.value = *given;
  if (parameter.minimum && parameter.maximum && *parameter.minimum > *parameter.maximum) {
    check.issue(job_reader::child(path, "min"),
                "min " + format_number(*parameter.minimum) + " above max " + format_number(*parameter.maximum),
                "a range with min <= max");
    return std::nullopt;
  }
  // The default against its range by the rule every parameter value meets (job_reader::check_parameter_value).
  job_reader::check_parameter_value(check, as_declared(parameter), value["value"], job_reader::child(path, "value"),
                                    "the default " + format_number(parameter.value));
  if (check.issue_count() != before) return std::nullopt;
  return parameter;
}

std::shared_ptr<const FormulaModel> read_object(const json& object, const std::string& pointer,
                                                std::vector<JobIssue>& issues) {
  Checker check(issues);
  const std::size_t before = check.issue_count();
  if (!check.object(object, pointer,
                    "an object {\"T\": ..., \"V\": ..., \"parameters\": {...}} or {\"H\": ..., \"parameters\": {...}}"))
    return nullptr;
  check.known_keys(object, pointer, formula_keys);
  FormulaModel model;
  if (const json* name = check.member(object, pointer, "name", false, "")) {
    if (name->is_string() && is_plugin_name(name->get<std::string>()))
      model.name = name->get<std::string>();
    else
      check.issue(job_reader::child(pointer, "name"), job_reader::describe(*name),
                  "a plugin name of lower-case letters, digits and '_' (at most 64, not starting with a digit)");
  }
  Symbols symbols;
  if (const json* parameters = check.member(object, pointer, "parameters", false, "")) {
    const std::string path = job_reader::child(pointer, "parameters");
    if (check.object(*parameters, path, "an object of parameter names and their default values")) {
      for (const auto& [name, value] : parameters->items()) {
        const std::string member = job_reader::child(path, name);
        if (!is_parameter_name(name)) {
          check.issue(member, "the parameter name \"" + name + "\"",
                      "a name of letters, digits and '_' (at most 64, not starting with a digit) that is not a "
                      "variable (q0, p1, ...), a function or pi");
          continue;
        }
        // A name the formulas may use even when its default or range is refused (one issue, not one per use).
        symbols.parameters.push_back(name);
        if (auto parameter = read_parameter(check, name, value, member))
          model.parameters.push_back(std::move(*parameter));
      }
    }
  }
  const bool read = object.contains("H") ? read_hamiltonian(check, object, pointer, symbols, model)
                                         : read_product_form(check, object, pointer, symbols, model);
  if (!read || check.issue_count() != before) return nullptr;
  const std::size_t used = model.dimension;
  if (const json* dimension = check.member(object, pointer, "dimension", false, ""))
    if (const auto n = check.integer(*dimension, job_reader::child(pointer, "dimension"),
                                     static_cast<std::int64_t>(used), static_cast<std::int64_t>(max_formula_dimension),
                                     "an integer from " + std::to_string(used) +
                                         " (the largest variable index used, plus one) to " +
                                         std::to_string(max_formula_dimension)))
      model.dimension = static_cast<std::size_t>(*n);
  for (const auto& [key, gradient] : {std::pair{"dT", &model.t_gradient}, std::pair{"dV", &model.v_gradient}})
    if (!gradient->empty() && gradient->size() != model.dimension)
      check.issue(job_reader::child(pointer, key), counted(gradient->size(), "component"),
                  "one component per variable: " + std::to_string(model.dimension) +
                      " (the model's dimension: the largest variable index used plus one, or \"dimension\")");
  if (check.issue_count() != before) return nullptr;
  return std::make_shared<const FormulaModel>(std::move(model));
}

}  // namespace

std::shared_ptr<const FormulaModel> read_formula_file(const std::filesystem::path& file,
                                                      std::vector<JobIssue>& issues) {
  const std::string where = file.string() + "#";
  std::error_code error;
  const auto size = std::filesystem::file_size(file, error);
  if (error || !std::filesystem::is_regular_file(file, error)) {
    issues.push_back({where, "no readable model file", "the path of a formula model file (JSON)"});
    return nullptr;
  }
  if (size > max_model_file_bytes) {
    issues.push_back({where, "a file of " + std::to_string(size) + " bytes", "a model file of at most 1 MiB"});
    return nullptr;
  }
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) {
    issues.push_back({where, "no readable model file", "the path of a formula model file (JSON)"});
    return nullptr;
  }
  std::vector<JobIssue> syntax;
  const auto document = parse_job_text(text.str(), syntax);
  for (auto& issue : syntax) issues.push_back({where + issue.path, issue.found, issue.allowed});
  if (!document) return nullptr;
  auto model = read_object(*document, where, issues);
  if (!model) return nullptr;
  auto located = std::make_shared<FormulaModel>(*model);
  located->file = file;
  return located;
}

std::shared_ptr<const FormulaModel> read_formula_model(const nlohmann::json& value, const std::string& pointer,
                                                       const std::filesystem::path& directory,
                                                       std::vector<JobIssue>& issues) {
  if (!value.is_string()) return read_object(value, pointer, issues);
  const std::string& path = value.get_ref<const std::string&>();
  if (path.empty() || path.find('\0') != std::string::npos) {
    issues.push_back({pointer, job_reader::describe(value), "the path of a model file, or a formula object"});
    return nullptr;
  }
  return read_formula_file(directory / path, issues);
}

std::vector<PluginParameter> declared_parameters(const FormulaModel& model) {
  std::vector<PluginParameter> declared;
  for (const FormulaParameter& parameter : model.parameters) declared.push_back(as_declared(parameter));
  return declared;
}

nlohmann::json formula_record(const FormulaModel& model, const std::string& cache_key) {
  json parameters = json::object();
  for (const FormulaParameter& parameter : model.parameters) parameters[parameter.name] = parameter.value;
  const bool product_form = !model.h_tree;
  return {{"name", model.name},
          {"H", product_form ? json(nullptr) : json(model.H)},
          {"T", product_form ? json(model.T) : json(nullptr)},
          {"V", product_form ? json(model.V) : json(nullptr)},
          {"K", model.k_tree ? json(model.K) : json(nullptr)},
          {"U", model.u_tree ? json(model.U) : json(nullptr)},
          {"parameters", parameters},
          {"dimension", model.dimension},
          {"file", model.file.empty() ? json(nullptr) : json(model.file.string())},
          {"cache_key", cache_key}};
}

}  // namespace nonsep::host::formula
