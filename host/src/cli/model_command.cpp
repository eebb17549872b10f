// `nonsep model compile FILE [-o NAME.so]` (a formula model file into a plugin) and the formula side of
// `nonsep validate` (formulas, parameters and dimensions checked without compiling).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/formula/cpp_source.hpp"
#include "nonsep/host/formula/plugin_cache.hpp"
#include "nonsep/host/study/scheme_choice.hpp"

namespace nonsep::host::cli {

namespace fs = std::filesystem;

int command_model_compile(const ModelCompileArguments& arguments) {
  std::vector<JobIssue> issues;
  const auto model = formula::read_formula_file(arguments.model_file, issues);
  if (!model) return report_invalid_job(InvalidJob(arguments.model_file, std::move(issues)));
  const fs::path output = arguments.output.empty() ? fs::path(model->name + ".so") : fs::path(arguments.output);
  if (output.filename() != model->name + ".so") {
    std::cerr << "nonsep: the plugin of the model '" << model->name << "' must be named " << model->name
              << ".so (the loader checks that a plugin's file is named after it), found " << output.string()
              << "; give -o " << (output.parent_path() / (model->name + ".so")).string()
              << " or set \"name\" in the model file\n";
    return to_int(ExitStatus::invalid_input);
  }
  if (arguments.print_source) {
    std::cout << formula::cpp_source(*model);
    return to_int(ExitStatus::success);
  }
  try {
    const auto toolchain = formula::find_toolchain(formula::PluginUse::share);
    const auto start = std::chrono::steady_clock::now();
    formula::compile_plugin(formula::cpp_source(*model), toolchain, output);
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.1f",
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    std::cout << "compiled " << arguments.model_file << " into " << output.string() << " in " << seconds
              << " s (load it with \"plugin\": \"" << output.string()
              << "\" or put its folder in NONSEP_PLUGIN_PATH)\n";
    return to_int(ExitStatus::success);
  } catch (const formula::FormulaCompileError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  }
}

namespace {

// The parameters a run would use: each declared one at the job's value, else at its default; those at their default
// are named after the object ("{"c": 0.5, "d": 1} (d by default)"); swept ones as parameters_text shows them.
std::string parameters_with_defaults(const Job& job, const std::vector<PluginParameter>& declared) {
  const nlohmann::json& given = job.parameters;
  nlohmann::json used = nlohmann::json::object();
  std::string defaults;
  for (const PluginParameter& parameter : declared) {
    const bool swept = std::any_of(job.sweep.begin(), job.sweep.end(),
                                   [&](const SweptParameter& sweep) { return sweep.name == parameter.name; });
    const bool set = given.contains(parameter.name) || swept;
    // A swept parameter is not in job.parameters (const operator[] of a missing key is undefined): parameters_text
    // writes its values over the placeholder.
    used[parameter.name] = given.contains(parameter.name) ? given.at(parameter.name)
                           : swept                        ? nlohmann::json()
                                                          : nlohmann::json(parameter.default_value);
    if (!set) defaults += (defaults.empty() ? "" : ", ") + parameter.name;
  }
  if (defaults.empty()) return parameters_text(used, job);
  return parameters_text(used, job) + " (" + defaults + (given.empty() ? ": the model's defaults)" : " by default)");
}

}  // namespace

std::optional<Job> read_formula_job(const std::string& job_file) {
  std::vector<JobIssue> issues;
  auto job = read_job(job_file, issues);
  // Not a formula job: load_job reads it again and reports its issues together with the plugin's.
  if (!job || !job->formula) return std::nullopt;
  if (!issues.empty()) throw InvalidJob(job_file, std::move(issues));
  check_formula_job(*job, issues);
  if (!issues.empty()) throw InvalidJob(job_file, std::move(issues));
  return job;
}

int report_formula_job(const std::string& job_file, const Job& job) {
  const formula::FormulaModel& model = *job.formula;
  std::cout << "valid: " << job_file << "\n"
            << "  model:       formula '" << model.name << "', dimension " << model.dimension
            << (model.file.empty() ? "" : " (" + model.file.string() + ")") << "\n"
            << (model.h_tree ? "    H = " + model.H + "\n"
                             : "    " + std::string(model.t_gradient.empty() ? "T = " : "") + model.T + "\n" + "    " +
                                   (model.v_gradient.empty() ? "V = " : "") + model.V + "\n")
            << "  parameters:  " << parameters_with_defaults(job, formula::declared_parameters(model)) << "\n"
            << (job.is_study()
                    ? ""
                    : integrator_line(job.run(),
                                      job.run().auto_scheme ? describe_auto(job, auto_model(model), false) : "",
                                      model.h_tree.has_value()))
            << sweep_text(job, false)
            << "  not compiled: the first run compiles it (or finds it in the cache); what needs the compiled model "
               "(initial states on an energy shell, the gradient check) is checked then\n";
  return to_int(ExitStatus::success);
}

}  // namespace nonsep::host::cli
