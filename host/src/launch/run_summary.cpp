#include "launch/run_summary.hpp"

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/json/finite_or_null.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/csv.hpp"

namespace nonsep::host {

using nlohmann::ordered_json;

namespace {

std::string hamiltonian_text(const Plugin& plugin, HamiltonianForm form) {
  return plugin.general_hamiltonian()   ? "H(q, p), the model's own"
         : form == HamiltonianForm::TTV ? "H = T_i(p) V_ij(q) T_j(p)"
                                        : "H = V_i(q) T_ij(p) V_j(q)";
}

ordered_json energy_facts(const RunFacts& facts) {
  const SingleRun& run = facts.loaded.job.run();
  const std::string hamiltonian = hamiltonian_text(facts.loaded.plugin, run.integrator.form);
  if (!facts.driver.energy_available())
    return {{"available", false},
            {"hamiltonian", hamiltonian},
            {"reason", "the plugin '" + facts.loaded.plugin.name() +
                           "' provides no Hessians (hessian_T and hessian_V), which " + hamiltonian + " needs"}};
  ordered_json largest = nullptr;
  if (const auto& l = facts.outcome.largest_energy_error)
    largest = {{"value", l->value}, {"trajectory", l->trajectory}};
  return {{"available", true},
          {"hamiltonian", hamiltonian},
          {"relative_error_definition", "(H - H0) / H0; unknown when H0 = 0"},
          {"evaluated_at",
           "step 0, every written sample (output.every), " +
               (run.energy_every > 0 ? "every " + ordinal(run.energy_every) + " step (output.energy_every), "
                                     : std::string()) +
               "the last step, and the final state of a trajectory that stopped early"},
          {"largest_relative_error", largest},
          {"max_relative_error_bound", finite_or_null(run.analysis.max_relative_energy_error)}};
}

// Which path stepped the run: the plugin's kernel (and its instruction set) or the evaluation path. Gauss-Legendre
// (`gauss`, `implicit_midpoint`) has one kernel, gauss_steps, with the numbers of the plugin's own flags (the
// baseline) whichever copy the plugin runs (nonsep/sdk/kernels.hpp, GaussKernels).
ordered_json stepping_facts(const RunFacts& facts, const std::string& scheme) {
  const KernelChoice& kernels = facts.loaded.plugin.kernels();
  const bool kernel = facts.driver.kernel_calls() > 0;
  if (scheme == "gauss" || scheme == "implicit_midpoint")
    return {{"path", kernel ? "kernel" : "evaluation"},
            {"instruction_set", kernel ? ordered_json("x86-64") : ordered_json(nullptr)},
            {"plugin_kernels", kernels.instruction_sets},
            {"note", kernel ? "the plugin's Gauss-Legendre kernel (gauss_steps): the evaluation path's numbers, from "
                              "the copy compiled with the plugin's own flags or a wider one without fused "
                              "multiply-adds"
                            : "the evaluations (the plugin has no Gauss-Legendre kernel, or "
                              "NONSEP_INSTRUCTION_SET=evaluation)"}};
  return {{"path", kernel ? "kernel" : "evaluation"},
          {"instruction_set", kernel ? ordered_json(kernels.chosen_name()) : ordered_json(nullptr)},
          {"plugin_kernels", kernels.instruction_sets},
          {"note", kernels.chosen && !kernel ? "every step needed the evaluation path (an every-step observer, tangent "
                                               "vectors of a scheme without a tangent kernel, or a scheme without "
                                               "basic steps)"
                                             : kernels.note}};
}

}  // namespace

ordered_json run_summary(const RunFacts& facts) {
  const Job& job = facts.loaded.job;
  const SingleRun& run = job.run();
  const auto description = Integrator::describe(run.integrator);
  const RunOutcome& outcome = facts.outcome;
  ordered_json summary;
  summary["status"] = to_string(outcome.status);
  if (!outcome.error.empty()) summary["error"] = outcome.error;
  summary["job"] = job.file.string();
  summary["model"] = {{"plugin", facts.loaded.plugin.name()},
                      {"version", facts.loaded.plugin.version()},
                      {"path", facts.loaded.plugin.path().string()},
                      {"dimension", job.initial.dimension},
                      {"parameters", ordered_json(facts.loaded.model.parameters())}};
  if (!job.sweep.empty()) {
    ordered_json swept = ordered_json::object();
    for (const SweptParameter& parameter : job.sweep) {
      summary["model"]["parameters"][parameter.name] = parameter.values;
      swept[parameter.name] = parameter.values.size();
    }
    summary["sweep"] = {
        {"parameters", swept},
        {"parameter_sets", job.parameter_sets()},
        {"order",
         "every parameter set (the product of the swept values, the parameters by name, the last varying fastest) "
         "with every initial state, set after set"},
        {"columns", "trajectories.csv: one column per swept parameter, after the others"}};
  }
  if (job.formula) summary["model"]["formula"] = formula::formula_record(*job.formula, job.formula_cache_key);
  summary["hamiltonian"] = hamiltonian_name(facts.loaded.plugin, run.integrator.form);
  summary["integrator"] = {{"scheme", description.scheme},
                           {"family", description.family},
                           {"order", description.order.to_string()},
                           {"t2", description.t2},
                           {"symplectic", description.symplectic},
                           {"time_reversible", description.time_reversible},
                           {"basic_steps_per_step", description.basic_steps_per_step}};
  summary["time"] = {{"dt", run.time.dt},
                     {"dt_requested", run.time.dt_requested},
                     {"steps", run.time.steps},
                     {"t_end", run.time.t_end},
                     {"steps_completed", outcome.steps_completed}};
  summary["energy"] = energy_facts(facts);
  const bool hdf5 = run.format == OutputFormat::hdf5;
  summary["output"] = {
      {"directory", facts.directory.string()},
      {"format", hdf5 ? "hdf5" : "csv"},
      {"trajectory", facts.samples_written && !hdf5 ? ordered_json("trajectory.csv") : ordered_json(nullptr)},
      {"trajectories", trajectories_file_name},
      {"every", run.every},
      {"energy_every", run.energy_every}};
  if (hdf5) summary["output"]["results"] = results_file_name;
  summary["trajectories"] = job.initial.count;
  summary["counts"] = {{"completed", outcome.counts.completed},
                       {"diverged", outcome.counts.diverged},
                       {"failed", outcome.counts.failed},
                       {"inaccurate", outcome.counts.inaccurate},
                       {"interrupted", outcome.counts.interrupted}};
  const auto evaluations = facts.driver.evaluations();
  summary["evaluations"] = {
      {"grad_T", evaluations.grad_T}, {"grad_V", evaluations.grad_V}, {"grad_H", evaluations.grad_H}};
  if (evaluations.grad_K + evaluations.grad_U > 0) {  // a model with a separable part K(p) + U(q)
    summary["evaluations"]["grad_K"] = evaluations.grad_K;
    summary["evaluations"]["grad_U"] = evaluations.grad_U;
  }
  summary["stepping"] = stepping_facts(facts, description.scheme);
  // What the scheme reports, under its family's name ("comparator": Tao's omega and largest copy distance).
  if (const std::vector<SchemeFigure> report = facts.driver.scheme_report(); !report.empty()) {
    ordered_json& figures = summary[find_scheme(run.integrator.scheme)->family];
    for (const SchemeFigure& figure : report) {
      figures[figure.name] = figure.value;
      if (!figure.note.empty()) figures[figure.name + "_note"] = figure.note;
    }
  }
  summary["wall_seconds"] = facts.wall_seconds;
  return summary;
}

void write_trajectories_csv(const std::filesystem::path& path, const RunFacts& facts,
                            std::span<const TrajectoryColumns* const> observers) {
  const std::size_t n = facts.loaded.job.initial.dimension;
  std::string text = "trajectory,status,step,t";
  for (const char* name : {"q", "p"})
    for (std::size_t i = 0; i < n; ++i) {
      text += ',';
      text += name;
      text += std::to_string(i);
    }
  text += ",H0,H,relative_energy_error,stop_step,stop_t,stop_variable,message";
  std::vector<std::string> columns;
  for (const TrajectoryColumns* observer : observers) observer->columns(columns);
  for (const std::string& column : columns) text += "," + column;
  const Job& job = facts.loaded.job;
  for (const SweptParameter& swept : job.sweep) text += "," + swept.name;
  text += '\n';
  // A sweep's cells of each parameter set, once.
  std::vector<std::string> set_cells(job.sweep.empty() ? 0 : job.parameter_sets());
  for (std::size_t s = 0; s < set_cells.size(); ++s) {
    const nlohmann::ordered_json parameters = job.parameter_set(s);
    for (const SweptParameter& swept : job.sweep) {
      const nlohmann::ordered_json& value = parameters[swept.name];
      set_cells[s] += ',';
      if (value.is_number_float())
        append_number(set_cells[s], value.get<double>());
      else
        set_cells[s] += value.dump();
    }
  }
  AtomicFile file(path);
  const auto& records = facts.outcome.trajectories;
  for (std::size_t index = 0; index < records.size(); ++index) {
    const TrajectoryRecord& record = records[index];
    text += std::to_string(index);
    text += ',';
    text += to_string(record.status);
    text += ',';
    text += std::to_string(record.final_step);
    text += ',';
    append_number(text, record.final_t);
    for (const auto* values : {&record.final_q, &record.final_p})
      for (std::size_t i = 0; i < n; ++i) {
        text += ',';
        if (i < values->size()) append_number(text, (*values)[i]);
      }
    text += ',';
    append_csv_number(text, record.energy_initial);
    text += ',';
    append_csv_number(text, record.energy_final);
    text += ',';
    append_csv_number(text, relative_energy_error(record.energy_final, record.energy_initial));
    text += ',';
    if (stopped_early(record.status)) {
      text += std::to_string(record.stop_step);
      text += ',';
      append_number(text, record.stop_t);
    } else {
      text += ',';
    }
    text += ',';
    append_csv_text(text, record.stop_variable);
    text += ',';
    append_csv_text(text, record.message);
    for (const TrajectoryColumns* observer : observers) observer->cells(index, text);
    if (!set_cells.empty()) text += set_cells[job.initial.parameter_set[index]];
    text += '\n';
    if (text.size() >= (1 << 16)) {
      file.write(text);
      text.clear();
    }
  }
  file.write(text);
  file.commit();
}

}  // namespace nonsep::host
