// `nonsep run`: loads the job, joins the MPI ranks, runs the job, the study or scheme auto's pilots and then the run
// under the stopping signals (stop_signals.hpp), and reports (run_reports.hpp).
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "cli/commands.hpp"
#include "cli/rank_output.hpp"
#include "cli/run_reports.hpp"
#include "cli/stop_signals.hpp"
#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/cluster/distributed_run.hpp"
#include "nonsep/host/cluster/ranks.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/observers/progress_bar.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/study/convergence_study.hpp"
#include "nonsep/host/study/scheme_choice.hpp"

namespace nonsep::host::cli {

namespace {

// Calls `start`; false, after saying why on stderr, when it threw what keeps a run from starting (the output
// folder, a checkpoint to resume from).
template <class Start>
bool started(Start start) {
  try {
    start();
    return true;
  } catch (const OutputError& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
  } catch (const FolderInUse& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
  } catch (const CheckpointError& error) {
    std::cerr << "nonsep: cannot resume: " << error.what() << "\n";
  }
  return false;
}

// Runs `run` (run_job or run_study) with SIGINT and SIGTERM caught. Nothing, after saying why on stderr, when it
// could not start (started); an interrupted outcome becomes "terminated" after SIGTERM or SIGUSR1.
template <class Run>
auto run_guarded(Run run) -> std::optional<decltype(run())> {
  InterruptGuard guard;
  std::optional<decltype(run())> outcome;
  if (!started([&] { outcome.emplace(run()); })) return std::nullopt;
  if (outcome->exit_status == ExitStatus::interrupted && stop_signal() != SIGINT)
    outcome->exit_status = ExitStatus::terminated;
  return outcome;
}

// Scheme "auto": puts the choice into the job and `options` and says what was chosen: on --resume the one the
// checkpoint recorded, else the pilots'. Nothing when the run can go on; else, after saying why on stderr, the exit
// status: the checkpoint cannot be resumed (2), no scheme could be chosen (1), a signal stopped the pilots (130, or
// 143 after SIGTERM or SIGUSR1; nothing was run, so nothing is left to resume).
std::optional<int> choose(LoadedJob& loaded, RunOptions& options, const RunArguments& arguments) {
  if (options.resume) {
    const std::filesystem::path checkpoint = options.output_directory / checkpoint_file_name;
    if (!started([&] {
          options.scheme_choice = recorded_scheme_choice(checkpoint);
          apply_recorded_choice(loaded, options.scheme_choice, checkpoint);
        }))
      return to_int(ExitStatus::invalid_input);
    if (!arguments.quiet)
      std::cout << "auto: " << options.scheme_choice["chosen"].get<std::string>()
                << " with dt = " << format_number(loaded.job.run().time.dt) << " (" << loaded.job.run().time.steps
                << " steps), as the interrupted run chose\n";
    return std::nullopt;
  }
  try {
    const SchemeChoice choice = choose_scheme(loaded, options);
    apply_choice(loaded.job, choice);
    options.scheme_choice = to_json(choice);
    if (!arguments.quiet) {
      const PilotResult& chosen = choice.pilots[choice.chosen];
      const std::string predicted = choice.chosen_by == AutoScheme::Measure::energy
                                        ? "chosen by the energy, predicted largest |dH/H0| "
                                        : "predicted error ";
      std::cout << "auto: " << chosen.candidate.label << " with dt = " << format_number(loaded.job.run().time.dt)
                << " (" << loaded.job.run().time.steps << " steps), " << predicted
                << format_number(chosen.predicted_error) << " for tolerance " << format_number(choice.tolerance)
                << "; pilots " << format_number(choice.pilot_seconds) << " s\n";
    }
    if (const std::string warning = choice_warning(choice); !warning.empty())
      std::cerr << "nonsep: " << warning << "\n";
    return std::nullopt;
  } catch (const PilotsInterrupted&) {
    const int signal = stop_signal();
    std::cerr << "nonsep: stopped by " << signal_name(signal)
              << " during the pilot runs of scheme auto, before the run began: nothing was run and nothing is left "
                 "to resume; run the job again to start over\n";
    return to_int(signal == SIGINT ? ExitStatus::interrupted : ExitStatus::terminated);
  } catch (const ChoiceFailed& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::run_failed);
  }
}

// Scheme "auto" in one process: signals are caught from before the pilots (a stop during them ends the command
// with a message), and the output folder is taken first, so that one the run may not use is refused before any
// pilot runs; then the choice and the run.
int run_auto(LoadedJob& loaded, RunOptions& options, const RunArguments& arguments) {
  const InterruptGuard guard;
  if (!started([&] {
        options.folder =
            std::make_shared<const RunFolder>(options.output_directory, "run", loaded.job.file, folder_use(options));
      }))
    return to_int(ExitStatus::invalid_input);
  if (const auto stopped = choose(loaded, options, arguments)) return *stopped;
  auto outcome = run_guarded([&] { return run_job(loaded, options); });
  return outcome ? report_run(*outcome, loaded.job, arguments, options.output_directory, stop_signal())
                 : to_int(ExitStatus::invalid_input);
}

// The run on this rank: every rank of a distributed run returns the same status; on the paths that rank 0 runs alone
// (a study, the resume of a one-process run) the others return 0.
int run_on_ranks(const RunArguments& arguments, const Ranks* ranks) {
  const OnlyRankZeroSpeaks quiet(*ranks);
  std::optional<LoadedJob> loaded;
  std::string invalid;
  try {
    loaded.emplace(load_job(arguments.job_file, ranks->size()));  // the memory check: a share per rank
  } catch (const InvalidJob& error) {
    invalid = error.what();
  }
  // A job or plugin that one rank cannot read (a node without the plugin): one message, exit 2 on every rank.
  if (const auto failure = ranks->first_failure(!invalid.empty(), invalid); failure.rank >= 0) {
    std::cerr << "nonsep: " << (failure.rank > 0 ? "rank " + std::to_string(failure.rank) + ": " : "")
              << failure.message << "\n";
    return to_int(ExitStatus::invalid_input);
  }
  if (arguments.resume && loaded->job.is_study()) {
    std::cerr << "nonsep: cannot resume: " << arguments.job_file
              << " is a convergence study (/study), which is not resumed; run it again without --resume\n";
    return to_int(ExitStatus::invalid_input);
  }
  RunOptions options;
  options.output_directory =
      arguments.output.empty() ? loaded->job.output_directory : std::filesystem::path(arguments.output);
  // Ranks share one stderr: they write lines, never a bar (distributed_run.cpp labels each rank's).
  if (!arguments.quiet)
    options.progress = stderr_is_terminal() && ranks->size() == 1 ? ProgressStyle::bar
                       : arguments.progress_every > 0             ? ProgressStyle::lines
                                                                  : ProgressStyle::none;
  options.progress_interval = arguments.progress_every;
  options.stop_requested = &stop_requested();
  options.resume = arguments.resume;
  options.force = arguments.force;
  options.threads = arguments.threads;
  reset_stop_request();
  // Work units over the ranks: a fresh run on several ranks, or the resume of such a run on any number.
  const bool plain_checkpoint = arguments.resume && !has_units(options.output_directory);
  if (!loaded->job.is_study() && (arguments.resume ? !plain_checkpoint : ranks->size() > 1)) {
    if (loaded->job.run().analysis.error_estimate || loaded->job.run().auto_scheme) {
      std::cerr << "nonsep: " << arguments.job_file << ": "
                << (loaded->job.run().auto_scheme ? "scheme \"auto\" (its pilots)"
                                                  : "/analysis/error_estimate (its half-step run)")
                << " runs in one process, not split over ranks or resumed from work units; run it without mpirun\n";
      return to_int(ExitStatus::invalid_input);
    }
    try {
      auto outcome = run_guarded([&] { return run_distributed(*loaded, options, *ranks); });
      return outcome ? report_run(*outcome, loaded->job, arguments, options.output_directory, stop_signal())
                     : to_int(ExitStatus::invalid_input);
    } catch (const RankFailure& failure) {
      std::cerr << "nonsep: " << failure.what() << "\n";
      return to_int(ExitStatus::invalid_input);
    }
  }
  // A study, or the resume of a one-process run: rank 0 does it, the others wait for its exit status.
  int status = 0;
  if (ranks->rank() == 0) {
    if (ranks->size() > 1 &&
        (loaded->job.is_study() || std::filesystem::exists(options.output_directory / checkpoint_file_name)))
      std::cerr << "nonsep: note: "
                << (loaded->job.is_study() ? "a convergence study" : "a one-process run's checkpoint")
                << " runs on rank 0 alone; the other " << ranks->size() - 1 << " rank(s) wait\n";
    if (loaded->job.is_study()) {
      auto outcome = run_guarded([&] { return run_study(*loaded, options); });
      status = outcome ? report_study(*outcome, options.output_directory, arguments.quiet)
                       : to_int(ExitStatus::invalid_input);
    } else {
      if (loaded->job.run().auto_scheme) {
        status = run_auto(*loaded, options, arguments);
      } else {
        auto outcome = run_guarded([&] { return run_job(*loaded, options); });
        status = outcome ? report_run(*outcome, loaded->job, arguments, options.output_directory, stop_signal())
                         : to_int(ExitStatus::invalid_input);
      }
    }
  }
  return status;
}

}  // namespace

int command_run(const RunArguments& arguments) {
  std::unique_ptr<Ranks> ranks;
  try {
    ranks = Ranks::join();
  } catch (const std::exception& error) {
    std::cerr << "nonsep: " << error.what() << "\n";
    return to_int(ExitStatus::invalid_input);
  }
  // Every rank ends with the largest status of all (rank 0 alone runs a study or a one-process resume).
  return ranks->max(run_on_ranks(arguments, ranks.get()));
}

}  // namespace nonsep::host::cli
