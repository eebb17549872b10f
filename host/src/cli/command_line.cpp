#include "nonsep/host/command_line.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <exception>
#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/platform/build_features.hpp"
#include "nonsep/host/platform/installation.hpp"

#ifndef NONSEP_VERSION
#error "NONSEP_VERSION must be defined by the build"
#endif

namespace nonsep::host {

using namespace cli;

namespace {

// An empty path names no file or folder: `--output ""` (an unset variable in a script) is refused, not taken for
// no --output at all.
const CLI::Validator non_empty_path(
    [](const std::string& path) {
      return path.empty() ? std::string("an empty path names no file or folder; give a path, or leave --output out")
                          : std::string();
    },
    "PATH");

// A number option's value: finite, and positive (or zero when `zero` is its meaning). CLI11's NonNegativeNumber and
// PositiveNumber let "nan" and "inf" through (every comparison with NaN is false).
CLI::Validator finite_number(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](const std::string& text) {
        double value = 0.0;
        const bool number = CLI::detail::lexical_cast(text, value);
        if (number && std::isfinite(value) && (value > 0.0 || (zero_allowed && value == 0.0))) return std::string();
        return "\"" + text + "\" is not a finite " + (zero_allowed ? "number >= 0" : "number > 0");
      },
      zero_allowed ? "NUMBER >= 0" : "NUMBER > 0");
}

}  // namespace

int run_command_line(int argc, char** argv) {
  try {
    CLI::App app{"nonsep " NONSEP_VERSION
                 ": explicit symplectic integrators for non-separable Hamiltonians H = T_i(p) V_ij(q) T_j(p)\n"
                 "(S. A. Chin). Models are plugins; runs are described by JSON job files. The manual (commands\n"
                 "and job files in its docs/user-guide.md): " +
                     manual_location(),
                 "nonsep"};
    app.set_version_flag("--version", [] { return build_features_text(); });
    app.require_subcommand(1);
    app.footer(schemes_text() + "\n" + exit_status_text() +
               "\nPlugins are searched in $NONSEP_PLUGIN_PATH (':'-separated), then the installed and the build "
               "tree's plugin folders.");

    RunArguments arguments;
    std::string job_file;
    InspectArguments inspect_arguments;

    auto* run = app.add_subcommand(
        "run",
        "Run a job: trajectory.csv (streamed), trajectories.csv and summary.json in the output folder "
        "(with /analysis/poincare also poincare.csv, with /analysis/lyapunov/every lyapunov.csv); a "
        "study (/study): convergence.csv, work_precision.csv, and summary.json with the fitted exponents");
    run->add_option("JOB.json", arguments.job_file, "the job file")->required();
    run->add_option("--output,-o", arguments.output,
                    "output folder, relative to the current directory (overrides the job's output.directory)")
        ->check(non_empty_path);
    run->add_flag("--quiet,-q", arguments.quiet, "no progress (bar or lines) and no completion line");
    run->add_option("--progress-every", arguments.progress_every,
                    "when stderr is not a terminal (a batch log), a plain progress line every SECONDS (time, percent, "
                    "max |dH/H0|, ETA; under mpirun each rank's, labelled with the rank and its work unit); 0: none")
        ->default_val(10.0)
        ->check(finite_number(true));
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
    run->footer(scheme_names_text() + "\n" + exit_status_text());

    auto* validate = app.add_subcommand(
        "validate", "Check a job without running it: plugin found, parameters valid, dimensions agree");
    validate->add_option("JOB.json", job_file, "the job file")->required();
    validate->footer(exit_status_text());

    auto* inspect = app.add_subcommand("inspect", "Show a plugin's metadata: parameters with defaults, ranges, units");
    inspect
        ->add_option("PLUGIN", inspect_arguments.name, "a plugin name (see `nonsep models`) or the path of a .so file")
        ->required();
    inspect->add_flag("--json", inspect_arguments.as_json, "print the raw metadata JSON");
    auto* check = inspect->add_flag("--check", inspect_arguments.check,
                                    "also compare the plugin's derivatives with finite differences; exit 1 if they "
                                    "disagree, 2 if nothing could be compared (dimension 0)");
    inspect
        ->add_option("--parameter", inspect_arguments.parameters,
                     "name=value: a model parameter for --check (repeatable; default: the plugin's defaults)")
        ->needs(check);
    inspect
        ->add_option("--job", inspect_arguments.parameters_job,
                     "JOB.json: --check with the model parameters of this job (--parameter overrides them)")
        ->needs(check);
    inspect
        ->add_option("--box", inspect_arguments.box,
                     "LO,HI: --check at 16 random points in [LO, HI]^n, each as p and as q (default -1.5,1.5)")
        ->needs(check);
    inspect
        ->add_option("--points-from", inspect_arguments.points_job,
                     "JOB.json: --check at the job's initial states (p for T, q for V) instead of random points "
                     "(as well, with --box)")
        ->needs(check);
    inspect
        ->add_option("--tolerance", inspect_arguments.tolerance,
                     "allowed error relative to max(1, |finite difference|) (default 1e-6)")
        ->check(finite_number(false))
        ->needs(check);
    inspect->footer(exit_status_text());

    auto* models = app.add_subcommand("models", "List the plugins on the search path, one line each");
    models->footer(exit_status_text());

    ExampleArguments example_arguments;
    auto* example = app.add_subcommand(
        "example",
        "Write a starting job file: the quickstart job, or the example NAME (see --list), to standard "
        "output or FILE; it passes `nonsep validate` as written");
    example->add_option("NAME", example_arguments.name, "the example (default: quickstart)");
    example->add_option("--output,-o", example_arguments.output, "the file to write (never overwritten)")
        ->check(non_empty_path);
    example->add_flag("--list", example_arguments.list, "list the examples, one line each")
        ->excludes(example->get_option("NAME"))
        ->excludes(example->get_option("--output"));
    example->footer(exit_status_text());

    auto* schema = app.add_subcommand(
        "schema",
        "Print the JSON Schema of job files (schemas/job.schema.json), generated from the job reader's "
        "tables and the scheme catalogue");
    schema->footer(exit_status_text());

    ModelCompileArguments model_arguments;
    auto* model = app.add_subcommand("model", "Formula models (docs/formula-models.md)");
    model->require_subcommand(1);
    auto* compile = model->add_subcommand(
        "compile", "Compile a formula model file into a plugin NAME.so (NAME: the model's \"name\")");
    compile->add_option("FILE", model_arguments.model_file, "the model file (JSON: T, V, parameters)")->required();
    compile->add_option("--output,-o", model_arguments.output, "the plugin file (default ./NAME.so)")
        ->check(non_empty_path);
    compile->add_flag("--print-source", model_arguments.print_source,
                      "print the C++ written from the formulas instead of compiling it");
    compile->footer(exit_status_text());

    // CLI11 would call an unknown command a missing subcommand without naming it.
    const auto named = [&](const CLI::App* command) { return command->check_name(argv[1]); };
    if (argc > 1 && argv[1][0] != '-' && app.get_subcommands(named).empty()) {
      const auto commands = app.get_subcommands([](const CLI::App*) { return true; });
      std::string names;
      for (std::size_t i = 0; i < commands.size(); ++i)
        names += (i == 0 ? "" : i + 1 == commands.size() ? " and " : ", ") + commands[i]->get_name();
      std::cerr << "nonsep: unknown command '" << argv[1] << "'; the commands are " << names
                << " (see nonsep --help)\n";
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
    if (inspect->parsed()) return command_inspect(inspect_arguments);
    if (models->parsed()) return command_models();
    if (example->parsed()) return command_example(example_arguments);
    if (schema->parsed()) return command_schema();
    if (compile->parsed()) return command_model_compile(model_arguments);
    return to_int(ExitStatus::invalid_input);
  } catch (const std::exception& error) {
    std::cerr << "nonsep: unexpected error: " << error.what() << "\n";
  } catch (...) {
    std::cerr << "nonsep: unexpected error of unknown type\n";
  }
  return to_int(ExitStatus::run_failed);
}

}  // namespace nonsep::host
