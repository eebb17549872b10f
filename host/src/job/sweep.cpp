// Parameter sweeps: /model/parameters/<name> given as several values (pass 2: read_swept_parameter,
// check_sweep_size), their values against the plugin's metadata (pass 3: check_swept_parameters), and the run's
// trajectories, the job's states once per parameter set, each set's on its own energy shell (make_trajectories).
#include <algorithm>
#include <cstdint>
#include <functional>
#include <utility>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/sdk/parameter_rules.hpp"
#include "sections.hpp"

namespace nonsep::host {

namespace job_reader {

std::optional<SweptParameter> read_swept_parameter(Checker& check, const std::string& name, const json& value,
                                                   const std::string& path) {
  SweptParameter swept{name, {}, path};
  if (value.is_array()) {
    if (value.empty() || value.size() > max_initial_states) {
      check.issue(path, "an array of " + std::to_string(value.size()) + " values",
                  "1 to " + std::to_string(max_initial_states) + " values to sweep over");
      return std::nullopt;
    }
    for (std::size_t i = 0; i < value.size(); ++i)
      if (!value[i].is_number() && !value[i].is_boolean()) {
        check.issue(child(path, i), describe(value[i]), "a number or true or false: one value of the sweep");
        return std::nullopt;
      }
    swept.values.assign(value.begin(), value.end());
    return swept;
  }
  swept.values_path = value.is_object() && value.contains("values") ? child(path, "values") : "";  // "": a range
  const auto axis = read_axis(check, value, path);
  if (!axis) return std::nullopt;
  for (const double x : *axis) swept.values.emplace_back(x);
  return swept;
}

void check_sweep_size(Checker& check, const Job& job) {
  if (job.sweep.empty()) return;
  std::size_t sets = 1;
  for (const SweptParameter& swept : job.sweep) {
    if (swept.values.empty()) return;
    if (sets > max_initial_states / swept.values.size()) {
      sets = max_initial_states + 1;
      break;
    }
    sets *= swept.values.size();
  }
  const std::size_t states = std::max<std::size_t>(1, job.initial.count),
                    n = std::max<std::size_t>(1, job.initial.dimension);
  if (sets > max_initial_states / states || sets * states > max_initial_values / n)
    check.issue("/model/parameters",
                (sets > max_initial_states ? "more than " + std::to_string(max_initial_states) : std::to_string(sets)) +
                    " parameter sets times " + std::to_string(states) + " initial states of dimension " +
                    std::to_string(n),
                "at most " + std::to_string(max_initial_states) + " trajectories (parameter sets times states) and " +
                    std::to_string(max_initial_values) + " numbers in q");
}

}  // namespace job_reader

std::size_t Job::parameter_sets() const {
  std::size_t sets = 1;
  for (const SweptParameter& swept : sweep) {
    if (swept.values.size() > 0 && sets > SIZE_MAX / swept.values.size()) return SIZE_MAX;  // refused by the reader
    sets *= swept.values.size();
  }
  return sets;
}

nlohmann::json Job::parameter_set(std::size_t s) const {
  nlohmann::json set = parameters;
  for (std::size_t k = sweep.size(); k-- > 0;) {
    const std::size_t size = sweep[k].values.size();
    set[sweep[k].name] = sweep[k].values[s % size];
    s /= size;
  }
  return set;
}

void check_swept_parameters(const Job& job, const std::vector<PluginParameter>& declared,
                            std::vector<JobIssue>& issues) {
  job_reader::Checker check(issues);
  for (const SweptParameter& swept : job.sweep) {
    const std::string path = job_reader::child("/model/parameters", swept.name);
    const PluginParameter* parameter = job_reader::find_parameter(check, declared, swept.name, path);
    if (!parameter) continue;
    for (std::size_t i = 0; i < swept.values.size(); ++i) {
      const nlohmann::json& value = swept.values[i];
      if (sdk::parameter_fault(parameter->type, parameter->minimum, parameter->maximum, value) ==
          sdk::ParameterFault::none)
        continue;  // the texts below only for a fault: a sweep may have a million values
      if (swept.values_path.empty())
        job_reader::check_parameter_value(
            check, *parameter, value, path,
            "the value " + job_reader::describe(value) + " (value " + std::to_string(i) + " of the range)");
      else
        job_reader::check_parameter_value(check, *parameter, value, job_reader::child(swept.values_path, i),
                                          "the value " + job_reader::describe(value));
    }
  }
}

namespace {

// The path of the first swept parameter whose value differs between sets a and b (the one a message names).
std::string differing_key(const Job& job, std::size_t a, std::size_t b) {
  const nlohmann::json first = job.parameter_set(a), second = job.parameter_set(b);
  for (const SweptParameter& swept : job.sweep)
    if (first[swept.name] != second[swept.name]) return job_reader::child("/model/parameters", swept.name);
  return "/model/parameters";
}

}  // namespace

bool for_each_parameter_set(const LoadedJob& loaded, std::vector<JobIssue>& issues,
                            const std::function<void(std::size_t, const PluginModel&)>& visit) {
  const Job& job = loaded.job;
  const std::size_t sets = job.parameter_sets(), n = loaded.model.dimension();
  for (std::size_t s = 0; s < sets; ++s) {
    if (s == 0) {
      visit(0, loaded.model);
      continue;
    }
    const std::string set = job.parameter_set(s).dump() + " (set " + std::to_string(s) + " of the sweep)";
    PluginModel model;
    try {
      model = loaded.plugin.create(job.parameter_set(s));
    } catch (const std::exception& error) {
      issues.push_back({"/model/parameters", "the parameter set " + set + ", refused by the plugin: " + error.what(),
                        "parameter sets the plugin accepts (see `nonsep inspect " + job.plugin + "`)"});
      return false;
    }
    if (model.dimension() != n) {
      issues.push_back({differing_key(job, 0, s),
                        "the parameter set " + set + ", whose model has dimension " +
                            std::to_string(model.dimension()) + " where set 0 (" + job.parameter_set(0).dump() +
                            ") has " + std::to_string(n),
                        "parameter sets of one dimension: a sweep cannot change the model's dimension (its "
                        "trajectories are stepped as one ensemble of states of one dimension, with one column per "
                        "component in its files); run one job per dimension"});
      return false;
    }
    visit(s, model);
  }
  return true;
}

void make_trajectories(LoadedJob& loaded, std::vector<JobIssue>& issues) {
  Job& job = loaded.job;
  InitialStates& initial = job.initial;
  const std::size_t sets = job.parameter_sets(), n = initial.dimension;
  // A sweep of one set still says whose each trajectory is (InitialStates::parameter_set).
  if (!initial.shell && job.sweep.empty()) return;
  // Too many trajectories: check_sweep_size reported it (this pass runs after a reader's issues too).
  if (n == 0 || sets > max_initial_states / std::max<std::size_t>(1, initial.count) ||
      sets * initial.count > max_initial_values / n)
    return;
  if (initial.shell && !loaded.plugin.has_energy()) {
    issues.push_back({"/initial/energy", "the plugin '" + loaded.plugin.name() + "', which cannot evaluate H",
                      "a plugin that evaluates H: value_H (a model given by H) or the Hessians hessian_T and "
                      "hessian_V (the product form)"});
    return;
  }
  const HamiltonianForm form = job.is_study() ? job.study().form : job.run().integrator.form;
  std::vector<double> all_q, all_p;
  std::vector<std::size_t> parameter_set;
  std::size_t left_out = 0;
  const bool every_set = for_each_parameter_set(loaded, issues, [&](std::size_t s, const PluginModel& model) {
    std::vector<double> q = initial.q, p = initial.p;
    if (initial.shell) left_out += solve_on_energy_shell(model, form, *initial.shell, n, q, p);
    all_q.insert(all_q.end(), q.begin(), q.end());
    all_p.insert(all_p.end(), p.begin(), p.end());
    parameter_set.insert(parameter_set.end(), q.size() / n, s);
  });
  if (!every_set) return;
  if (initial.shell && all_q.empty()) {
    const EnergyShell& shell = *initial.shell;
    issues.push_back({"/initial/energy",
                      format_number(shell.energy) + ", which no state of the grid reaches" +
                          (sets > 1 ? " with any parameter set" : ""),
                      "an energy that some states of the grid reach by solving for " + shell.solve_for + " (H at " +
                          shell.solve_for.substr(shell.negative ? 1 : 0) + " = 0 must not exceed it)"});
    return;
  }
  if (initial.shell) initial.shell->left_out = left_out;
  initial.q = std::move(all_q);
  initial.p = std::move(all_p);
  initial.count = initial.q.size() / n;
  if (!job.sweep.empty()) initial.parameter_set = std::move(parameter_set);
}

}  // namespace nonsep::host
