#include "nonsep/host/command_line.hpp"

#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"

#ifndef NONSEP_VERSION
#error "NONSEP_VERSION must be defined by the build"
#endif

namespace nonsep::host {

using namespace cli;

int run_command_line(int argc, char** argv) {
  try {
    CLI::App app{"nonsep " NONSEP_VERSION
                 ": explicit symplectic integrators for non-separable Hamiltonians H = T_i(p) V_ij(q) T_j(p)\n"
                 "(S. A. Chin). Models are plugins; runs are described by JSON job files (README.md, section\n"
                 "Running nonsep).",
                 "nonsep"};
    app.set_version_flag("--version", "nonsep " NONSEP_VERSION);
    app.require_subcommand(1);
    app.footer(schemes_text() + "\n" + exit_status_text() +
               "\nPlugins are searched in $NONSEP_PLUGIN_PATH (':'-separated), then the installed and the build "
               "tree's plugin folders.");

    RunArguments arguments;
    std::string job_file, plugin_name;
    bool as_json = false, check = false;

    auto* run = app.add_subcommand("run",
                                   "Run a job: trajectory.csv (streamed), trajectories.csv and summary.json in the output folder "
                                   "(with /analysis/poincare also poincare.csv, with /analysis/lyapunov/every lyapunov.csv); a "
                                   "study (/study): convergence.csv, and summary.json with the fitted exponents");
    run->add_option("JOB.json", arguments.job_file, "the job file")->required();
    run->add_option("--output,-o", arguments.output,
                    "output folder, relative to the current directory (overrides the job's output.directory)");
    run->add_flag("--quiet,-q", arguments.quiet, "no progress bar and no completion line");
    run->add_flag("--resume", arguments.resume,
                  "continue an interrupted run from checkpoint.json in its output folder; the outputs end as those of "
                  "an uninterrupted run");
    run->add_flag("--force", arguments.force,
                  "start over in an output folder that holds another job's results or an interrupted run's "
                  "checkpoint, removing every file of the earlier run")
        ->excludes(run->get_option("--resume"));
    run->add_option("--threads,-j", arguments.threads,
                    "worker threads for the ensemble (default: all cores); results are bit-identical for any number")
        ->check(CLI::Range(1u, 4096u));
    run->footer(schemes_text() + "\n" + exit_status_text());

    auto* validate = app.add_subcommand(
        "validate", "Check a job without running it: plugin found, parameters valid, dimensions agree");
    validate->add_option("JOB.json", job_file, "the job file")->required();
    validate->footer(exit_status_text());

    auto* inspect = app.add_subcommand("inspect", "Show a plugin's metadata: parameters with defaults, ranges, units");
    inspect->add_option("PLUGIN", plugin_name, "a plugin name (see `nonsep models`) or the path of a .so file")
        ->required();
    inspect->add_flag("--json", as_json, "print the raw metadata JSON");
    inspect->add_flag("--check", check,
                      "also compare the plugin's derivatives with finite differences (default parameters); exit 1 "
                      "if they disagree");
    inspect->footer(exit_status_text());

    auto* models = app.add_subcommand("models", "List the plugins on the search path, one line each");
    models->footer(exit_status_text());

    // CLI11 would call an unknown command a missing subcommand without naming it.
    const auto named = [&](const CLI::App* command) { return command->check_name(argv[1]); };
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands(named).empty()) {
      std::cerr << "nonsep: unknown command '" << argv[1]
                << "'; the commands are run, validate, inspect and models (see nonsep --help)\n";
      return to_int(ExitStatus::invalid_input);
    }
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
      const int code = app.exit(error);
      return code == 0 ? to_int(ExitStatus::success) : to_int(ExitStatus::invalid_input);
    }
    if (run->parsed()) return command_run(arguments);
    if (validate->parsed()) return command_validate(job_file);
    if (inspect->parsed()) return command_inspect(plugin_name, as_json, check);
    if (models->parsed()) return command_models();
    return to_int(ExitStatus::invalid_input);
  } catch (const std::exception& error) {
    std::cerr << "nonsep: unexpected error: " << error.what() << "\n";
  } catch (...) {
    std::cerr << "nonsep: unexpected error of unknown type\n";
  }
  return to_int(ExitStatus::run_failed);
}

}  // namespace nonsep::host
