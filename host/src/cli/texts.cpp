#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::cli {

std::string exit_status_text() {
  return "Exit status:\n"
         "  0    success\n"
         "  1    the run started but failed: a trajectory diverged, the plugin failed mid-run, or a trajectory\n"
         "       was retired as inaccurate (its |dH/H0| passed analysis.max_relative_energy_error; summary.json\n"
         "       says which and where); an output could not be written; `inspect --check` found wrong derivatives\n"
         "  2    invalid input, nothing was run: usage, job file, parameters, a plugin that cannot be loaded\n"
         "       or whose gradients disagree with its values at the initial states, an output folder that\n"
         "       cannot be created\n"
         "  130  interrupted (SIGINT): the current step was finished, outputs written with status \"interrupted\",\n"
         "       and a checkpoint: `nonsep run JOB --resume` continues the run\n"
         "  143  terminated (SIGTERM, or SIGUSR1 as mpirun passes it on): the same as 130\n";
}

// Generated from nonsep::scheme_catalogue(), like the job reader's checks.
std::string schemes_text() {
  std::string text = "Integrator schemes (job file: \"integrator\": {\"scheme\": name, option: value, ...}):\n";
  for (const auto& scheme : scheme_catalogue()) {
    text += "  " + scheme.name + " [family " + scheme.family + "]: " + scheme.method + ", " + scheme.equations + "; " +
            (scheme.symplectic ? "symplectic" : "not symplectic") + ", " +
            (scheme.time_reversible ? "time-reversible" : "not time-reversible") + "\n";
    text += "      " + scheme.summary + "\n";
    for (const auto& parameter : scheme.parameters)
      text += "      " + parameter.name + " (" +
              (parameter.default_text.empty() ? std::string("required") : "default " + parameter.default_text) +
              "): " + parameter.description + "\n";
  }
  return text;
}

std::string scheme_names_text() {
  std::string names;
  for (const auto& scheme : scheme_catalogue()) names += (names.empty() ? "" : ", ") + scheme.name;
  return "Integrator schemes: " + names +
         " (`nonsep --help` describes each with its options; docs/user-guide.md, \"Integrator schemes\"), or auto "
         "with a tolerance (docs/user-guide.md, \"Scheme auto\").\n";
}

int report_invalid_job(const InvalidJob& error) {
  std::cerr << "nonsep: " << error.what() << "\n";
  return to_int(ExitStatus::invalid_input);
}

std::string time_text(const TimeGrid& time) {
  return std::to_string(time.steps) + " steps of dt = " + format_number(time.dt) +
         " to t_end = " + format_number(time.t_end) +
         (time.from_t_end && time.dt != time.dt_requested ? " (dt requested " + format_number(time.dt_requested) + ")"
                                                          : "");
}

}  // namespace nonsep::host::cli
