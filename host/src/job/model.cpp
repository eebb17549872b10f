// /model: the plugin's name or path and its parameters as written (pass 2), and the parameters against the loaded
// plugin's metadata (pass 3, check_model_parameters) by the rule the SDK and the loader share,
// nonsep::sdk::parameter_fault.
#include <algorithm>

#include "nonsep/host/formula/formula_model.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

void read_model(Checker& check, const json& document, Job& job) {
  const std::string what =
      "an object {\"plugin\": name or path, \"parameters\": {...}} or {\"formula\": {\"T\": ..., \"V\": ...}}";
  const json* model = check.member(document, "", "model", document_keys()["model"].required, what);
  if (!model || !check.object(*model, "/model", what)) return;
  const KeyTable& keys = model_keys();
  check.known_keys(*model, "/model", keys.names());
  if (model->contains("plugin") == model->contains("formula"))
    check.issue("/model",
                model->contains("plugin") ? "both \"plugin\" and \"formula\"" : "neither \"plugin\" nor \"formula\"",
                "exactly one of \"plugin\" (a compiled model) and \"formula\" (T and V as formulas, "
                "docs/formula-models.md)");
  const std::string plugin_what = "a plugin name (see `nonsep models`) or a path to a .so file";
  if (const json* plugin = check.member(*model, "/model", "plugin", false, plugin_what))
    if (auto name = check.path_string(*plugin, "/model/plugin", plugin_what)) job.plugin = *name;
  if (const json* formula = check.member(*model, "/model", "formula", false, ""))
    job.formula = formula::read_formula_model(*formula, "/model/formula", job.directory, check.issues());
  if (const json* parameters = check.member(*model, "/model", "parameters", false, ""))
    if (check.object(*parameters, "/model/parameters", "an object of the plugin's parameters (see `nonsep inspect`)"))
      for (const auto& [name, value] : parameters->items()) {
        if (!value.is_array() && !value.is_object()) {
          job.parameters[name] = value;
        } else if (auto swept = read_swept_parameter(check, name, value, child("/model/parameters", name))) {
          job.sweep.push_back(std::move(*swept));
        }
      }
}

}  // namespace nonsep::host::job_reader

namespace nonsep::host::job_reader {

const PluginParameter* find_parameter(Checker& check, const std::vector<PluginParameter>& declared,
                                      const std::string& name, const std::string& path) {
  const auto it = std::find_if(declared.begin(), declared.end(),
                               [&](const PluginParameter& parameter) { return parameter.name == name; });
  if (it != declared.end()) return &*it;
  std::string names;
  for (const auto& parameter : declared) names += (names.empty() ? "" : ", ") + parameter.name;
  check.issue(path, "the unknown parameter \"" + name + "\"",
              names.empty() ? "none: this plugin has no parameters" : "the plugin's parameters " + names);
  return nullptr;
}

}  // namespace nonsep::host::job_reader

namespace nonsep::host {

void check_model_parameters(const nlohmann::json& given, const std::vector<PluginParameter>& declared,
                            std::vector<JobIssue>& issues) {
  job_reader::Checker check(issues);
  for (const auto& [name, value] : given.items()) {
    const std::string path = job_reader::child("/model/parameters", name);
    if (const PluginParameter* parameter = job_reader::find_parameter(check, declared, name, path))
      job_reader::check_parameter_value(check, *parameter, value, path, job_reader::describe(value));
  }
}

}  // namespace nonsep::host
