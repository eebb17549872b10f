// The key tables of job files (job_keys.hpp). Descriptions are the schema's; the limits are the reader's own
// constants (job.hpp, time_grid.hpp).
#include "job_keys.hpp"

#include <limits>
#include <stdexcept>

#include "nonsep/host/job.hpp"

namespace nonsep::host::job_reader {

std::vector<std::string> KeyTable::names() const {
  std::vector<std::string> names;
  for (const auto& rule : rules) names.push_back(rule.name);
  return names;
}

std::vector<std::string> KeyTable::required() const {
  std::vector<std::string> names;
  for (const auto& rule : rules)
    if (rule.required) names.push_back(rule.name);
  return names;
}

const KeyRule& KeyTable::operator[](std::string_view name) const {
  for (const auto& rule : rules)
    if (rule.name == name) return rule;
  throw std::logic_error("the job reader has no rule for the key \"" + std::string(name) + "\"");
}

const KeyTable& document_keys() {
  static const KeyTable table{{
      {.name = "$schema",
       .type = ValueType::string,
       .description = "The schema the file follows (for editors); ignored by nonsep.",
       .allowed = "a string (the JSON Schema the file follows; ignored by nonsep)"},
      {.name = "description",
       .type = ValueType::text,
       .description = "Free text; ignored by nonsep.",
       .allowed = "a string (free text, ignored by nonsep)"},
      {.name = "model",
       .type = ValueType::object,
       .required = true,
       .description = "The model plugin.",
       .allowed =
           "an object {\"plugin\": name or path, \"parameters\": {...}} or {\"formula\": {\"T\": ..., \"V\": ...}}",
       .keys = model_keys},
      {.name = "hamiltonian",
       .type = ValueType::form,
       .default_value = "TTV",
       .description = "TTV: H = T_i(p) V_ij(q) T_j(p); VVT: H = V_i(q) T_ij(p) V_j(q).",
       .allowed = "\"TTV\" (H = T_i V_ij T_j, the default) or \"VVT\" (H = V_i T_ij V_j)"},
      {.name = "integrator",
       .type = ValueType::defined,
       .description = "The scheme and its options (a run; required there, refused in a study).",
       .definition = "integrator",
       .run_only = true,
       .in_study_found = "an integrator together with /study",
       .in_study_allowed = "no /integrator in a study: each entry of /study/integrators is one"},
      {.name = "initial",
       .type = ValueType::defined,
       .required = true,
       .description = "One state, a non-empty array of states (an ensemble), a grid of states, or states from a "
                      ".npy or .csv file; a study has one state.",
       .allowed = "one state {\"q\": [...], \"p\": [...]}, an array of such states, {\"grid\": {\"q\": [axes], \"p\": "
                  "[axes]}} or {\"file\": \"states.npy\"}",
       .definition = "initial"},
      {.name = "time",
       .type = ValueType::object,
       .required = true,
       .description = "The time grid: {dt, t_end or steps} for a run, {t_end} for a study (whose step sizes are its "
                      "integrators').",
       .allowed = "an object with \"dt\" and either \"t_end\" or \"steps\" (a run), or {\"t_end\": T} (a study: every "
                  "integrator runs to T with its own step counts)"},
      {.name = "output", .type = ValueType::object, .description = "Where results go.", .keys = output_keys},
      {.name = "analysis",
       .type = ValueType::object,
       .description = "Per-trajectory analysis of a run (not of a study).",
       .keys = analysis_keys,
       .run_only = true,
       .in_study_found = "an analysis together with /study",
       .in_study_allowed = "/analysis in single runs only"},
      {.name = "study",
       .type = ValueType::object,
       .description = "A convergence study: each integrator runs from the one initial state to time.t_end at each of "
                      "its step counts; outputs convergence.csv and the fitted exponents in summary.json. Step "
                      "counts come from the integrator's own steps or dt, else from the study's.",
       .keys = study_keys},
      {.name = "checkpoint",
       .type = ValueType::object,
       .description = "When checkpoint.json is saved in the output folder, for `nonsep run JOB --resume`. Always "
                      "saved when a run is interrupted. Runs only: a study is not resumed.",
       .keys = checkpoint_keys,
       .run_only = true,
       .in_study_found = "a checkpoint policy together with /study",
       .in_study_allowed = "/checkpoint in single runs only (a study is not resumed)"},
  }};
  return table;
}

const KeyTable& model_keys() {
  static const KeyTable table{
      {
          {.name = "plugin",
           .type = ValueType::path,
           .description =
               "A plugin name (looked up as <name>.so on the search path, see `nonsep models`) or a path to a "
               ".so file (contains '/' or ends in .so; relative to the job file's folder).",
           .allowed = "a plugin name (see `nonsep models`) or a path to a .so file"},
          {.name = "formula",
           .type = ValueType::defined,
           .description = "Instead of a plugin: T(p) and V(q) as formulas (or the path of a model file holding them), "
                          "compiled on first use into a cached plugin (docs/formula-models.md).",
           .definition = "formula"},
          {.name = "parameters",
           .type = ValueType::defined,
           .default_value = nlohmann::ordered_json::object(),
           .description = "The plugin's parameters by name (see `nonsep inspect PLUGIN`); missing ones take the "
                          "plugin's defaults.",
           .definition = "parameters"},
      },
      {{KeyPair::Kind::exactly_one, "plugin", "formula",
        "exactly one of \"plugin\" (a compiled model) and \"formula\" (T and V as formulas, "
        "docs/formula-models.md)"}}};
  return table;
}

const KeyTable& run_time_keys() {
  static const KeyTable table{
      {
          {.name = "dt",
           .type = ValueType::nonzero,
           .required = true,
           .description = "Time step; negative integrates backwards (t_end must then be negative too).",
           .allowed = "the time step, a finite non-zero number (negative integrates backwards in time)"},
          {.name = "t_end",
           .type = ValueType::nonzero,
           .description = "End time, same sign as dt. steps = ceil((t_end/dt)(1 - 1e-9)), and the step actually used "
                          "is t_end/steps, so the run ends exactly at t_end.",
           .allowed = "the end time, a finite non-zero number of the same sign as dt"},
          {.name = "steps",
           .type = ValueType::integer,
           .minimum = 1,
           .maximum = steps_limit,
           .description = "Number of steps of exactly dt."},
      },
      {{KeyPair::Kind::exactly_one, "t_end", "steps",
        "exactly one of \"t_end\" (the time to end at) and \"steps\" (the number of steps of dt)"}}};
  return table;
}

const KeyTable& study_time_keys() {
  static const KeyTable table{{
      {.name = "t_end",
       .type = ValueType::nonzero,
       .required = true,
       .description = "The end time of every run of the study.",
       .allowed = "the end time, a finite non-zero number (negative integrates backwards)"},
  }};
  return table;
}

const KeyTable& output_keys() {
  static const KeyTable table{{
      {.name = "directory",
       .type = ValueType::path,
       .description = "Output folder, relative to the job file's folder; default <job file name without .json>.out "
                      "beside the job file. `nonsep run --output DIR` overrides it.",
       .allowed = "a folder name or path, relative to the job file's folder"},
      {.name = "every",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = int64_limit,
       .default_value = 1,
       .description = "trajectory.csv gets steps 0, every, 2 every, ... and the final step; 0 writes no "
                      "trajectory.csv. Not in a study (it writes no samples).",
       .allowed = "an integer >= 0: write every n-th step to trajectory.csv (0: no trajectory)"},
      {.name = "energy_every",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = int64_limit,
       .default_value = 0,
       .description = "H is evaluated at step 0, at every written sample and at the end; energy_every > 0 also "
                      "evaluates it every energy_every-th step. Costs about a step's work per evaluation. Not in a "
                      "study (it measures the energy error at every step).",
       .allowed = "an integer >= 0: also evaluate H every n-th step (0: only at the written samples, the start and "
                  "the end)"},
      {.name = "format",
       .type = ValueType::choice,
       .default_value = "csv",
       .description = "\"csv\": the samples in trajectory.csv. \"hdf5\": the samples in results.h5 (group /samples) "
                      "instead, and trajectories.csv, poincare.csv and lyapunov.csv copied into it at the end (the CSV "
                      "files are kept); needs a build with HDF5 (`nonsep --version`). A study accepts \"csv\" only.",
       .choices = {"csv", "hdf5"}},
  }};
  return table;
}

const KeyTable& checkpoint_keys() {
  static const KeyTable table{{
      {.name = "every_steps",
       .type = ValueType::integer,
       .minimum = 0,
       .maximum = steps_limit,
       .default_value = 0,
       .description = "Save a checkpoint every n steps; 0: not by steps.",
       .allowed = "an integer from 0 to " + std::to_string(steps_limit) +
                  ": save a checkpoint every n steps (0: not by steps)"},
      {.name = "every_seconds",
       .type = ValueType::nonnegative,
       .default_value = 60,
       .description = "Save a checkpoint when this many seconds of wall time have passed since the last one; 0: "
                      "not by time.",
       .allowed = "a finite number >= 0: save a checkpoint every s seconds of wall time (0: not by time)"},
  }};
  return table;
}

const KeyTable& study_keys() {
  static const KeyTable table{
      {
          {.name = "integrators",
           .type = ValueType::defined,
           .required = true,
           .description = "The integrators, each as /integrator of a run with an optional label and its own steps or "
                          "dt.",
           .allowed = "a non-empty array of integrators, each as /integrator of a run",
           .definition = "study_integrators"},
          {.name = "steps", .type = ValueType::defined, .definition = "step_counts"},
          {.name = "dt", .type = ValueType::defined, .definition = "step_sizes"},
          {.name = "reference",
           .type = ValueType::defined,
           .description = "The exact state at t_end: convergence.csv then has each run's phase-space error "
                          "|(q, p) - (q_ref, p_ref)|, and the fits its exponent.",
           .definition = "state"},
          {.name = "reference_run",
           .type = ValueType::defined,
           .description =
               "Instead of reference: an integrator with exactly one step count (\"steps\": [N]) or size, "
               "run first from the initial state to t_end; its end state is the reference of the phase-space "
               "errors (summary.json study.reference says which).",
           .definition = "study_integrator"},
          {.name = "repeats",
           .type = ValueType::integer,
           .minimum = 1,
           .maximum = 1000,
           .default_value = 1,
           .description = "How many times each run is repeated for its wall time: work_precision.csv gives the median "
                          "over the repeats and their count (the errors and evaluation counts are those of the first: "
                          "every repeat computes the same numbers).",
           .allowed = "a whole number of repeats from 1 to 1000"},
      },
      {{KeyPair::Kind::at_most_one, "steps", "dt",
        "either \"steps\" (step counts over t_end) or \"dt\" (step sizes), not both"},
       {KeyPair::Kind::at_most_one, "reference", "reference_run",
        "either \"reference\" (the state at t_end) or \"reference_run\" (an integrator that computes it)"}}};
  return table;
}

const KeyTable& study_integrator_keys() {
  static const KeyTable table{
      {
          {.name = "label",
           .type = ValueType::string,
           .description = "The integrator's name in convergence.csv and the fits; default \"<scheme> <order>\" "
                          "(\"basic\" for the basic step); distinct per integrator.",
           .allowed = "a non-empty string naming the integrator"},
          {.name = "steps", .type = ValueType::defined, .definition = "step_counts"},
          {.name = "dt", .type = ValueType::defined, .definition = "step_sizes"},
      },
      {{KeyPair::Kind::at_most_one, "steps", "dt",
        "either \"steps\" (step counts over t_end) or \"dt\" (step sizes), not both"}}};
  return table;
}

const std::vector<FormName>& hamiltonian_forms() {
  static const std::vector<FormName> forms{{"TTV", HamiltonianForm::TTV}, {"VVT", HamiltonianForm::VVT}};
  return forms;
}

}  // namespace nonsep::host::job_reader
