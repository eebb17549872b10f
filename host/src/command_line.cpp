#include "nonsep/host/command_line.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "nonsep/core/integrator_description.hpp"
#include "nonsep/host/checkpoint.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output_files.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/plugin_report.hpp"
#include "nonsep/host/progress_bar.hpp"
#include "nonsep/host/runner.hpp"
#include "nonsep/host/study.hpp"

#ifndef NONSEP_VERSION
#error "NONSEP_VERSION must be defined by the build"
#endif

namespace nonsep::host {

namespace {

std::atomic<bool> stop_requested{false};
std::atomic<int> stop_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the stop flags must be lock-free to be set in a signal handler");

extern "C" void request_stop(int signal) {
  stop_signal.store(signal);
  stop_requested.store(true);
}

// Catches the first SIGINT or SIGTERM (the run finishes its step, flushes trajectory.csv and writes its checkpoint
// and summary); SA_RESETHAND restores the default action, so a second signal of the same kind ends the process at
// once. No SA_RESTART: a plugin sleeping or waiting in a system call sees EINTR and returns sooner.
class InterruptGuard {
 public:
  InterruptGuard() {
    struct sigaction action = {};
    action.sa_handler = request_stop;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, &previous_interrupt_);
    sigaction(SIGTERM, &action, &previous_terminate_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &previous_interrupt_, nullptr);
    sigaction(SIGTERM, &previous_terminate_, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_interrupt_ = {}, previous_terminate_ = {};
};

std::string exit_status_text() {
  return "Exit status:\n"
         "  0    success\n"
         "  1    the run started but failed: a trajectory diverged or the plugin failed mid-run (summary.json\n"
         "       says which and where); an output could not be written; `inspect --check` found wrong derivatives\n"
         "  2    invalid input, nothing was run: usage, job file, parameters, a plugin that cannot be loaded,\n"
         "       an output folder that cannot be created\n"
         "  130  interrupted (SIGINT): the current step was finished, outputs written with status \"interrupted\",\n"
         "       and a checkpoint: `nonsep run JOB --resume` continues the run\n"
         "  143  terminated (SIGTERM): the same as 130\n";
}

// Generated from nonsep::scheme_catalogue(), like the job reader's checks.
std::string schemes_text() {
  std::string text = "Integrator schemes (job file: \"integrator\": {\"scheme\": name, option: value, ...}):\n";
  for (const auto& scheme : scheme_catalogue()) {
    text += "  " + scheme.name + ": " + scheme.method + ", " + scheme.equations + "; " +
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

int report_invalid_job(const InvalidJob& error) {
  std::cerr << "nonsep: " << error.what() << "\n";
  return to_int(ExitStatus::invalid_input);
}

std::string time_text(const TimeGrid& time) {
  return std::to_string(time.steps) + " steps of dt = " + format_number(time.dt) + " to t_end = " +
         format_number(time.t_end) +
         (time.from_t_end && time.dt != time.dt_requested ? " (dt requested " + format_number(time.dt_requested) + ")"
                                                          : "");
}

// The end of a study: one line per integrator with its fitted exponent, or what went wrong.
int report_study(const RunOutcome& outcome, const std::filesystem::path& directory, bool quiet) {
  const auto& summary = outcome.summary;
  const auto& runs = summary["study"]["runs"];
  std::string line = summary["status"].get<std::string>() + ": study of " + std::to_string(summary["fits"].size()) +
                     " integrators, " + std::to_string(runs["completed"].get<std::size_t>()) + " runs completed";
  for (const char* other : {"diverged", "failed", "interrupted"})
    if (runs[other].get<std::size_t>() > 0) line += ", " + std::to_string(runs[other].get<std::size_t>()) + " " + other;
  line += "; results in " + directory.string();
  std::ostream& out = outcome.exit_status == ExitStatus::success ? std::cout : std::cerr;
  if (outcome.exit_status != ExitStatus::success || !quiet) {
    out << (outcome.exit_status == ExitStatus::success ? "" : "nonsep: ") << line << "\n";
    for (const auto& fit : summary["fits"])
      out << "  " << fit["integrator"].get<std::string>() << ": energy error exponent "
          << (fit["exponent"].is_null() ? std::string("(no fit)") : format_number(fit["exponent"].get<double>()))
          << " (nominal " << fit["order"].get<std::string>() << ")\n";
  }
  if (summary.contains("error")) std::cerr << "nonsep: " << summary["error"].get<std::string>() << "\n";
  if (summary.contains("failures"))
    for (const auto& failure : summary["failures"])
      std::cerr << "nonsep: " << failure["integrator"].get<std::string>() << " with " << failure["steps"]
                << " steps " << failure["status"].get<std::string>() << ": " << failure["error"].get<std::string>()
                << "\n";
  return to_int(outcome.exit_status);
}

int command_run(const std::string& job_file, const std::string& output, bool quiet, bool resume,
                unsigned threads) {
  std::optional<LoadedJob> loaded;
  try {
    loaded.emplace(load_job(job_file));
  } catch (const InvalidJob& error) {
    return report_invalid_job(error);
  }
  if (resume && loaded->job.study) {
    std::cerr << "nonsep: cannot resume: " << job_file << " is a convergence study (/study), which is not resumed; "
              << "run it again without --resume\n";
    return to_int(ExitStatus::invalid_input);
  }
  RunOptions options;
  options.output_directory = output.empty() ? loaded->job.output_directory : std::filesystem::path(output);
  options.show_progress = !quiet && stderr_is_terminal();
  options.stop_requested = &stop_requested;
  options.resume = resume;
  options.threads = threads;
  stop_requested.store(false);
  stop_signal.store(0);
  RunOutcome outcome;
  {
    InterruptGuard guard;
    try {
      outcome = loaded->job.study ? run_study(*loaded, options) : run_job(*loaded, options);
    } catch (const OutputError& error) {
      std::cerr << "nonsep: " << error.what() << "\n";
      return to_int(ExitStatus::invalid_input);
    } catch (const CheckpointError& error) {
      std::cerr << "nonsep: cannot resume: " << error.what() << "\n";
      return to_int(ExitStatus::invalid_input);
    }
  }
  if (outcome.exit_status == ExitStatus::interrupted && stop_signal.load() == SIGTERM)
    outcome.exit_status = ExitStatus::terminated;
  if (loaded->job.study) return report_study(outcome, options.output_directory, quiet);
  const auto& summary = outcome.summary;
  const auto& counts = summary["counts"];
  const std::string status = summary["status"].get<std::string>();
  const std::size_t trajectories = outcome.trajectories.size();
  std::string line = status + ": " + std::to_string(trajectories) + (trajectories == 1 ? " trajectory (" : " trajectories (") +
                     std::to_string(counts["completed"].get<std::size_t>()) + " completed";
  for (const char* other : {"diverged", "failed", "interrupted"})
    if (counts[other].get<std::size_t>() > 0)
      line += ", " + std::to_string(counts[other].get<std::size_t>()) + " " + other;
  line += "), " + time_text(loaded->job.time) + "; results in " + options.output_directory.string();
  if (outcome.exit_status == ExitStatus::success) {
    if (!quiet) std::cout << line << "\n";
  } else {
    std::cerr << "nonsep: " << line << "\n";
    if (summary.contains("error")) std::cerr << "nonsep: " << summary["error"].get<std::string>() << "\n";
    if (status == "interrupted")
      std::cerr << "nonsep: stopped by " << (stop_signal.load() == SIGTERM ? "SIGTERM" : "SIGINT") << " after step "
                << summary["time"]["steps_completed"] << "; `nonsep run " << job_file
                << (output.empty() ? "" : " --output " + output) << " --resume` continues from there\n";
    // One line per stopped trajectory, up to a screenful: an ensemble may have thousands (all are in the summary).
    constexpr std::size_t shown_at_most = 20;
    std::size_t stopped = 0;
    for (std::size_t index = 0; index < outcome.trajectories.size(); ++index) {
      const TrajectoryRecord& trajectory = outcome.trajectories[index];
      if (trajectory.status != "diverged" && trajectory.status != "failed") continue;
      if (++stopped > shown_at_most) continue;
      if (trajectory.status == "diverged")
        std::cerr << "nonsep: trajectory " << index << " diverged at step " << trajectory.diverged_step
                  << ", t = " << format_number(trajectory.diverged_t) << " (" << trajectory.diverged_variable
                  << " is not finite)\n";
      else if (!trajectory.error.empty())
        std::cerr << "nonsep: trajectory " << index << " failed: " << trajectory.error << "\n";
    }
    if (stopped > shown_at_most)
      std::cerr << "nonsep: ... and " << stopped - shown_at_most << " more trajectories that diverged or failed; "
                << (options.output_directory / "summary.json").string() << " lists them all\n";
  }
  return to_int(outcome.exit_status);
}

int command_validate(const std::string& job_file) {
  try {
    const LoadedJob loaded = load_job(job_file);
    const Job& job = loaded.job;
    const auto& spec = job.integrator;
    if (job.study) {
      std::cout << "valid: " << job_file << "\n"
                << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
                << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
                << "  study:       " << job.study->integrators.size() << " integrators to t_end = "
                << format_number(job.time.t_end) << (job.study->reference_q.empty() ? "" : ", with a reference")
                << "\n";
      for (const auto& integrator : job.study->integrators)
        std::cout << "    " << integrator.label << ": " << integrator.spec.scheme << ", order "
                  << integrator.spec.order.to_string() << ", t2 = " << format_number(integrator.spec.t2) << ", "
                  << integrator.steps.size() << " step counts " << integrator.steps.front() << ".."
                  << integrator.steps.back() << " (" << integrator.steps_from << ")\n";
      std::cout << "  output:      " << job.output_directory.string() << "\n";
      return to_int(ExitStatus::success);
    }
    std::cout << "valid: " << job_file << "\n"
              << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
              << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
              << "  parameters:  " << loaded.model.parameters().dump() << "\n"
              << "  integrator:  " << spec.scheme << ", order " << spec.order.to_string() << ", t2 = "
              << format_number(spec.t2) << ", H_" << (spec.form == HamiltonianForm::TTV ? "TTV" : "VVT") << "\n"
              << "  initial:     " << job.initial.count << " state" << (job.initial.count == 1 ? "" : "s") << " ("
              << job.initial.shape << ")\n"
              << "  time:        " << time_text(job.time) << "\n"
              << "  output:      " << job.output_directory.string() << ", trajectory every " << job.every
              << (job.every == 0 ? " (none)" : " steps") << "\n";
    return to_int(ExitStatus::success);
  } catch (const InvalidJob& error) {
    return report_invalid_job(error);
  }
}

int command_inspect(const std::string& name, bool as_json, bool check) {
  std::optional<Plugin> plugin;
  try {
    plugin = load_plugin(name, std::filesystem::current_path());
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  }
  if (as_json)
    std::cout << plugin->metadata().dump(2) << "\n";
  else
    std::cout << describe_plugin(*plugin);
  if (!check) return to_int(ExitStatus::success);
  try {
    const PluginModel model = plugin->create(nlohmann::json::object());
    const DerivativeCheck result = check_derivatives(model, *plugin);
    (as_json ? std::cerr : std::cout) << "derivative check of " << plugin->name() << " (default parameters, dimension "
                                      << model.dimension() << "):\n"
                                      << result.text;
    return to_int(result.passed ? ExitStatus::success : ExitStatus::run_failed);
  } catch (const PluginError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  } catch (const ModelError& error) {
    std::cerr << "nonsep: derivative check failed: the plugin could not evaluate: " << error.what() << "\n";
    return to_int(ExitStatus::run_failed);
  }
}

int command_models() {
  const auto discovered = discover_plugins();
  for (const auto& entry : discovered) std::cout << describe_discovered(entry) << "\n";
  if (discovered.empty()) {
    std::cerr << "nonsep: no plugins found; searched:";
    for (const auto& directory : plugin_search_path()) std::cerr << " " << directory.string();
    std::cerr << "\n";
  }
  return to_int(ExitStatus::success);
}

}  // namespace

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
               "tree's plugin folders. NONSEP_FUSED=0 makes runs step through the plugin's gradients instead of its "
               "integrate() (the same results, slower; for comparisons).");

    std::string job_file, output, plugin_name;
    bool quiet = false, as_json = false, check = false, resume = false;
    unsigned threads = 0;

    auto* run = app.add_subcommand("run",
                                   "Run a job: trajectory.csv (streamed) and summary.json in the output folder; a "
                                   "study (/study): convergence.csv, and summary.json with the fitted exponents");
    run->add_option("JOB.json", job_file, "the job file")->required();
    run->add_option("--output,-o", output,
                    "output folder, relative to the current directory (overrides the job's output.directory)");
    run->add_flag("--quiet,-q", quiet, "no progress bar and no completion line");
    run->add_flag("--resume", resume,
                  "continue an interrupted run from checkpoint.json in its output folder; the outputs end as those of "
                  "an uninterrupted run");
    run->add_option("--threads,-j", threads,
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
    if (run->parsed()) return command_run(job_file, output, quiet, resume, threads);
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
