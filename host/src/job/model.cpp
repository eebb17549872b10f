// /model: the plugin's name or path and its parameters as written (pass 2), and the parameters against the loaded
// plugin's metadata (pass 3, check_model_parameters) by the rule the SDK and the loader share,
// nonsep::sdk::parameter_fault.
#include <algorithm>

#include "nonsep/host/formula/formula_model.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

void read_model(Checker& check, const KeyReader& document, Job& job) {
  const json* model = document.value("model");
  if (!model) return;
  const KeyReader keys(check, *model, "/model", model_keys(), allowed_text(document_keys()["model"]));
  if (!keys.is_object()) return;
  if (const auto plugin = keys.string("plugin")) job.plugin = *plugin;
  if (const json* formula = keys.value("formula"))
    job.formula = formula::read_formula_model(*formula, "/model/formula", job.directory, check.issues());
  if (const json* parameters = keys.value("parameters"))
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
