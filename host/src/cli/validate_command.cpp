#include <cmath>
#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/core/analysis/frequency_map_indicator.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/study/scheme_choice.hpp"

namespace nonsep::host::cli {
namespace {

// "grid on the energy shell H = 7, p1 solved for; 36 of its 144 states cannot reach it and are left out": without
// it, a grid of 144 points that validates as "108 states (grid)" looks like a mistake in the grid.
std::string initial_shell_text(const InitialStates& initial, bool sweep) {
  if (!initial.shell) return "";
  const EnergyShell& shell = *initial.shell;
  return " on the energy shell H = " + format_number(shell.energy) + ", " + shell.solve_for + " solved for; " +
         std::to_string(shell.left_out) + " of its " + std::to_string(initial.count + shell.left_out) +
         (sweep ? " (parameter set, state) pairs" : " states") + " cannot reach it and are left out";
}

}  // namespace

// "triplet, order 4/3, t2 = -1.8171205928321397": the scheme, the order it has and its other catalogue options.
std::string integrator_text(const IntegratorSpec& spec) {
  std::string text = spec.scheme + ", order " + Integrator::describe(spec).order.to_string();
  for (const auto& parameter : find_scheme(spec.scheme)->parameters) {
    if (parameter.name == "order") continue;
    const auto value = option_value(spec, parameter);
    text += ", " + parameter.name + " = " +
            (std::holds_alternative<Fraction>(value) ? std::get<Fraction>(value).to_string()
                                                     : format_number(std::get<double>(value)));
  }
  return text;
}

std::string integrator_line(const SingleRun& run, const std::string& auto_text, bool given_by_h) {
  const std::string form = given_by_h                                    ? "H given by the model"
                           : run.integrator.form == HamiltonianForm::TTV ? "H_TTV"
                                                                         : "H_VVT";
  return "  integrator:  " + (run.auto_scheme ? auto_text : integrator_text(run.integrator)) + ", " + form + "\n";
}

std::string parameters_text(nlohmann::json parameters, const Job& job) {
  for (const SweptParameter& swept : job.sweep) {
    const auto& values = swept.values;
    if (values.size() <= 8) {
      parameters[swept.name] = values;
    } else {
      parameters[swept.name] = std::to_string(values.size()) + " values: " + values[0].dump() + ", " +
                               values[1].dump() + ", ..., " + values.back().dump();
    }
  }
  return parameters.dump();
}

std::string sweep_text(const Job& job, bool loaded) {
  if (job.sweep.empty()) return "";
  std::string text = "  sweep:       ";
  for (const SweptParameter& swept : job.sweep)
    text +=
        (&swept == &job.sweep.front() ? "" : " x ") + swept.name + " (" + counted(swept.values.size(), "value") + ")";
  const std::size_t sets = job.parameter_sets();
  const std::size_t states =
      loaded ? (job.initial.count + (job.initial.shell ? job.initial.shell->left_out : 0)) / sets : job.initial.count;
  text += ": " + counted(sets, "parameter set") + " x " + counted(states, "state") + " = " +
          counted(sets * states, "trajectory", "trajectories");
  if (!job.initial.shell) return text + "\n";
  if (!loaded) return text + ", less those the energy shell leaves out\n";
  return text + ", " + std::to_string(job.initial.count) + " of them on the energy shell\n";
}

// What /analysis/frequencies will sample and write, or "" without it.
std::string frequencies_text(const SingleRun& run, std::size_t dimension, std::size_t trajectories) {
  std::string text;
  for (const auto& indicator : run.analysis.sampled_indicators()) {
    const auto* map = dynamic_cast<const FrequencyMapIndicator*>(indicator.get());
    if (!map) continue;
    const std::size_t signals = map->degrees().empty() ? dimension : map->degrees().size();
    const std::uint64_t samples = run.time.steps / map->every();
    const double bytes =
        static_cast<double>(trajectories) * static_cast<double>(signals) * static_cast<double>(samples) * 16.0;
    text += "  frequencies: " + counted(signals, "signal") + " q_k + i p_k, " + std::to_string(samples) +
            " samples every " + counted(map->every(), "step") + " (tau = " + format_number(run.time.dt * map->every()) +
            "), " + FrequencyMapIndicator::signals_file_name + " " + format_number(std::round(bytes / 1e5) / 10.0) +
            " MB" +
            (map->spectra() > 0 ? ", " + std::string(FrequencyMapIndicator::spectra_file_name) + " with " +
                                      counted(map->spectra(), "term") + " a signal"
                                : "") +
            "\n";
  }
  return text;
}

int command_validate(const std::string& job_file) {
  try {
    if (const auto formula_job = read_formula_job(job_file)) return report_formula_job(job_file, *formula_job);
    const LoadedJob loaded = load_job(job_file);
    const Job& job = loaded.job;
    if (job.is_study()) {
      const Study& study = job.study();
      std::cout << "valid: " << job_file << "\n"
                << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
                << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
                << "  study:       " << study.integrators.size()
                << " integrators to t_end = " << format_number(study.t_end)
                << (study.reference_q.empty() ? "" : ", with a reference") << "\n";
      for (const auto& integrator : study.integrators)
        std::cout << "    " << integrator.label << ": " << integrator_text(integrator.spec) << ", "
                  << integrator.steps.size() << " step counts " << integrator.steps.front() << ".."
                  << integrator.steps.back() << " (" << integrator.steps_from << ")\n";
      std::cout << "  output:      " << job.output_directory.string() << "\n";
      return to_int(ExitStatus::success);
    }
    const SingleRun& run = job.run();
    std::cout << "valid: " << job_file << "\n"
              << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
              << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
              << "  parameters:  " << parameters_text(loaded.model.parameters(), job) << "\n"
              << integrator_line(run, run.auto_scheme ? describe_auto(loaded) : "", loaded.plugin.general_hamiltonian())
              << "  initial:     " << job.initial.count
              << (job.sweep.empty() ? (job.initial.count == 1 ? " state" : " states")
                                    : (job.initial.count == 1 ? " trajectory" : " trajectories"))
              << " (" << job.initial.shape << initial_shell_text(job.initial, !job.sweep.empty()) << ")\n"
              << sweep_text(job, true) << "  time:        " << time_text(run.time) << "\n"
              << "  output:      " << job.output_directory.string() << ", trajectory every " << run.every
              << (run.every == 0 ? " (none)" : " steps") << "\n"
              << frequencies_text(run, loaded.model.dimension(), job.initial.count);
    return to_int(ExitStatus::success);
  } catch (const InvalidJob& error) {
    return report_invalid_job(error);
  }
}

}  // namespace nonsep::host::cli
