#pragma once
// A model written as formulas, in a job (/model/formula) or in a model file the job names. Its JSON shape:
//   {"name": "pdm_oscillator",                      optional: the plugin's name, [a-z_][a-z0-9_]*, default "formula"
//    "T": "p0^2 / (2 * (1 + alpha * ...))",         required: T(p), a formula of p0, p1, ... (expression.hpp)
//    "V": "q0^2 / 4",                               required: V(q), a formula of q0, q1, ...
//    "dT": ["sqrt((1 + p0^2)/2)", ...],             instead of T: its gradient, n formulas of p (one per p_i)
//    "dV": [...],                                   instead of V: its gradient, n formulas of q
//                                                   (H_TTV and H_VVT need the gradients and Hessians of T and V,
//                                                   never their values; the plugin's value_T, value_V then throw)
//    "K": "...", "U": "alpha^2 * q0^2 / 2",         optional: a separable part K(p) + U(q) of H
//                                                   (H = T_i V_ij T_j + K + U, nonsep/sdk/model_adapter.hpp)
//    "parameters": {"alpha": 0.5},                  optional: names (is_parameter_name) and their default values;
//                                                   or {"c": {"value": 0.2, "min": -0.1, "max": 0.3}}: a default
//                                                   and its allowed range (inclusive, either bound optional),
//                                                   which the compiled plugin declares as a plugin's table does, so
//                                                   that values and sweeps outside it are refused
//    "dimension": 2}                                optional: n (1..64); default the largest index used plus one
// or, for a Hamiltonian of any shape, instead of T, V, dT, dV, K and U:
//   {"H": "(p0 - q1)^2 / 2 + ...", ...}             H(q, p), a formula of q0, q1, ..., p0, p1, ...: a model given
//                                                   by H (gauss, implicit_midpoint and tao integrate it; Chin's
//                                                   schemes need the product form)
// /model/formula is that object, or a string: the path of a JSON file holding it (relative to the job's folder).
// The parameters are numbers; a job's /model/parameters overrides their defaults as for any plugin, within their
// ranges.
// Every problem is a JobIssue at a JSON Pointer (in the job, or "<model file>#/V" in a model file); a formula's
// issue quotes it and points at the column (expression.hpp). Nothing is compiled here.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/host/formula/expression.hpp"
#include "nonsep/host/json/issues.hpp"
#include "nonsep/host/plugin_loader.hpp"

namespace nonsep::host::formula {

// What the plugin of a formula model says of each parameter.
inline constexpr const char* formula_parameter_description = "a parameter of the formulas";

struct FormulaParameter {
  std::string name;
  double value = 0.0;                      // the default
  std::optional<double> minimum, maximum;  // the allowed range, inclusive; absent: unbounded
};

struct FormulaModel {
  std::string name = "formula";
  std::optional<Node> h_tree;  // a model given by H(q, p): its tree, and T, V, K, U and their trees unused
  std::string H;               // its canonical text; empty for the product form
  std::string T, V;            // canonical text (print) of the trees: what the metadata and summary.json show
  Node t_tree, v_tree;
  // When given by their gradients ("dT", "dV"): n trees each, and T (V) is "grad T = [..., ...]", t_tree (v_tree)
  // unused. Empty otherwise.
  std::vector<Node> t_gradient, v_gradient;
  std::string K, U;  // the separable part's canonical text; empty when absent
  std::optional<Node> k_tree, u_tree;
  std::vector<FormulaParameter> parameters;  // in the order of the JSON object (by name)
  std::size_t dimension = 1;
  std::filesystem::path file;  // the model file it came from; empty when written in the job
};

// Reads /model/formula (an object, or the path of a model file relative to `directory`). `pointer` is where the
// value is ("/model/formula"). Nothing, with issues added, when anything is wrong.
std::shared_ptr<const FormulaModel> read_formula_model(const nlohmann::json& value, const std::string& pointer,
                                                       const std::filesystem::path& directory,
                                                       std::vector<JobIssue>& issues);

// Reads a model file (`nonsep model compile FILE`); issues at "<file>#/...".
std::shared_ptr<const FormulaModel> read_formula_file(const std::filesystem::path& file, std::vector<JobIssue>& issues);

// The JSON Schema of /model/formula (the job schema's $defs/formula).
nlohmann::ordered_json formula_schema();

// What summary.json records of a formula model: {"H" (canonical, or null for the product form), "T", "V" (canonical;
// "grad T = [...]" when given by "dT"; null for a model given by H),
// "parameters" (defaults), "dimension", "file" (the model file, or null), "cache_key"}.
nlohmann::json formula_record(const FormulaModel& model, const std::string& cache_key);

// The formula's parameters as the plugin metadata will declare them (for checking a job's /model/parameters
// without compiling).
std::vector<PluginParameter> declared_parameters(const FormulaModel& model);

}  // namespace nonsep::host::formula
