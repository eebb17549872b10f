#include <time.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <streambuf>
#include <string>
#include <vector>

#include "cli/commands.hpp"
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

std::atomic<bool> stop_requested{false};
std::atomic<int> stop_signal{0};
std::atomic<std::int64_t> first_stop_nanoseconds{0};  // CLOCK_MONOTONIC of the first stopping signal
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the stop flags must be lock-free to be set in a signal handler");

// A second signal this soon after the first is the same request delivered twice, not the user insisting:
// `timeout` signals the process and then its process group (the process again), mpirun may pass a signal on more
// than once, and a scheduler signals every process of the job.
constexpr std::int64_t repeat_window_nanoseconds = 1'000'000'000;

std::int64_t monotonic_nanoseconds() {
  timespec now{};
  ::clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

extern "C" void request_stop(int signal) {
  const std::int64_t now = monotonic_nanoseconds();
  std::int64_t first = 0;
  if (first_stop_nanoseconds.compare_exchange_strong(first, now)) {
    stop_signal.store(signal);
    stop_requested.store(true);
    return;
  }
  if (now - first < repeat_window_nanoseconds) return;
  // The user insists: the signal's default action (the process ends at once, killed by it), delivered when this
  // handler returns, the signal being blocked while it runs.
  struct sigaction default_action = {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  ::sigaction(signal, &default_action, nullptr);
  ::raise(signal);
}

// Catches SIGINT, SIGTERM and SIGUSR1: the first stops the run (it finishes its step, flushes trajectory.csv and
// writes its checkpoint and summary). Any of them again, more than repeat_window_nanoseconds after the first, ends
// the process at once; earlier it is taken for the same request delivered twice and ignored. No SA_RESTART: a
// plugin sleeping or waiting in a system call sees EINTR and returns sooner.
class InterruptGuard {
 public:
  InterruptGuard() {
    struct sigaction action = {};
    action.sa_handler = request_stop;
    sigemptyset(&action.sa_mask);
    for (int signal : {SIGINT, SIGTERM, SIGUSR1}) sigaddset(&action.sa_mask, signal);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, &previous_interrupt_);
    sigaction(SIGTERM, &action, &previous_terminate_);
    // mpirun passes SIGUSR1 on to every rank (SIGTERM and SIGINT it does not), and Slurm's --signal=USR1@SECONDS
    // warns a job with it before its time is up: it stops a run as SIGTERM does (docs/cluster.md).
    sigaction(SIGUSR1, &action, &previous_user1_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &previous_interrupt_, nullptr);
    sigaction(SIGTERM, &previous_terminate_, nullptr);
    sigaction(SIGUSR1, &previous_user1_, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction previous_interrupt_ = {}, previous_terminate_ = {}, previous_user1_ = {};
};

// Under MPI only rank 0 prints: the others' std::cout and std::cerr go nowhere while the run command lasts.
class OnlyRankZeroSpeaks {
 public:
  explicit OnlyRankZeroSpeaks(const Ranks& ranks) {
    if (ranks.rank() == 0) return;
    out_ = std::cout.rdbuf(&nowhere_);
    err_ = std::cerr.rdbuf(&nowhere_);
  }
  ~OnlyRankZeroSpeaks() {
    if (out_) std::cout.rdbuf(out_);
    if (err_) std::cerr.rdbuf(err_);
  }
  OnlyRankZeroSpeaks(const OnlyRankZeroSpeaks&) = delete;
  OnlyRankZeroSpeaks& operator=(const OnlyRankZeroSpeaks&) = delete;

 private:
  struct Nowhere : std::streambuf {
    int overflow(int c) override { return c; }
  } nowhere_;
  std::streambuf* out_ = nullptr;
  std::streambuf* err_ = nullptr;
};

// Round-off also shows as errors at the smallest dt this many times above the nominal power law through the
// largest dt (StudyFit::energy_error_excess_at_smallest_dt), when they are small enough to be round-off at all
// (round_off_at_most, study/convergence_study.hpp).
constexpr double flattened_excess = 10.0;

std::string four_digits(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%#.4g", x);
  return text;
}

// What makes a study's fit unreliable, with what to do: runs left out at the round-off floor, an energy error that
// reaches round-off or flattens at the smallest dt, errors that rise as dt shrinks (a non-monotone ladder). One
// sentence each; none for a clean fit.
std::vector<std::string> fit_warnings(const StudyFit& fit) {
  std::vector<std::string> warnings;
  if (fit.points_at_round_off > 0)
    warnings.push_back(fit.integrator + ": " + std::to_string(fit.points_at_round_off) +
                       (fit.points_at_round_off == 1 ? " run" : " runs") +
                       " at the round-off floor of the energy error (dt <= " + four_digits(*fit.round_off_dt_max) +
                       ", |dH/H0| down to " + four_digits(*fit.round_off_error_smallest) +
                       ") left out of the fit, which has " + std::to_string(fit.points) +
                       " points; move its step range to larger dt (fewer steps) to fit on all of them");
  const auto& smallest = fit.energy_error_smallest;
  const auto& excess = fit.energy_error_excess_at_smallest_dt;
  std::string round_off;
  if (smallest && *smallest < round_off_energy_error)
    round_off = "its smallest |dH/H0| is " + four_digits(*smallest) + ", at the round-off of double precision";
  else if (excess && smallest && *excess > flattened_excess && *smallest < round_off_at_most)
    round_off = "at the smallest dt it is " + four_digits(*excess) + " times what the nominal exponent " +
                four_digits(fit.description.order.value()) +
                " predicts from the largest dt: the errors flatten, as round-off makes them";
  if (!round_off.empty())
    warnings.push_back(fit.integrator + ": the energy error reaches round-off: " + round_off +
                       (fit.dt_min ? " (dt_min = " + four_digits(*fit.dt_min) + ")" : std::string()) +
                       "; move its step range to larger dt (fewer steps) so that every point is above it");
  const auto rises = [&](const std::optional<NonMonotoneStep>& rise, const std::string& what) {
    if (!rise) return;
    warnings.push_back(fit.integrator + ": the " + what + " is not monotone in dt: " + four_digits(rise->error_fine) +
                       " at " + std::to_string(rise->steps_fine) + " steps against " + four_digits(rise->error_coarse) +
                       " at " + std::to_string(rise->steps_coarse) +
                       " (a larger dt), so no power law describes the ladder and the fitted exponent is not the "
                       "order: the larger dt are pre-asymptotic, or the error oscillates with dt; move its step "
                       "range to smaller dt (more steps), where the error falls at every halving");
  };
  rises(fit.energy_error_rises, "largest |dH/H0| over the run");
  rises(fit.phase_error_rises, "phase error at t_end");
  return warnings;
}

// The end of a study: one line per integrator with its fitted exponent, or what went wrong; then warnings about
// fits that round-off or a sign change make unreliable (on stderr, also with --quiet).
int report_study(const StudyOutcome& outcome, const std::filesystem::path& directory, bool quiet) {
  const StatusCounts& runs = outcome.run_counts;
  std::string line = std::string(to_string(outcome.status)) + ": study of " + std::to_string(outcome.fits.size()) +
                     " integrators, " + std::to_string(runs.completed) + " runs completed";
  const std::pair<const char*, std::size_t> others[] = {
      {"diverged", runs.diverged}, {"failed", runs.failed}, {"interrupted", runs.interrupted}};
  for (const auto& [other, count] : others)
    if (count > 0) line += ", " + std::to_string(count) + " " + other;
  line += "; results in " + directory.string();
  std::ostream& out = outcome.exit_status == ExitStatus::success ? std::cout : std::cerr;
  if (outcome.exit_status != ExitStatus::success || !quiet) {
    out << (outcome.exit_status == ExitStatus::success ? "" : "nonsep: ") << line << "\n";
    for (const auto& fit : outcome.fits)
      out << "  " << fit.integrator << ": energy error exponent "
          << (fit.exponent ? four_digits(*fit.exponent) : std::string("(no fit)")) << " (nominal "
          << fit.description.order.to_string() << " = " << four_digits(fit.description.order.value()) << ")"
          << (fit_warnings(fit).empty() ? "" : " (see warning)") << "\n";
  }
  out.flush();
  for (const auto& fit : outcome.fits)
    for (const auto& warning : fit_warnings(fit)) std::cerr << "nonsep: warning: " << warning << "\n";
  if (!outcome.error.empty()) std::cerr << "nonsep: " << outcome.error << "\n";
  for (std::size_t i = 0; i < outcome.fits.size(); ++i)
    for (const StudyRun& run : outcome.runs[i])
      if (run.status == TrajectoryStatus::diverged || run.status == TrajectoryStatus::failed)
        std::cerr << "nonsep: " << outcome.fits[i].integrator << " with " << run.steps << " steps "
                  << to_string(run.status) << ": " << run.error << "\n";
  return to_int(outcome.exit_status);
}

}  // namespace

namespace {

// A run whose relative energy error grew larger than this gets a warning even without a bound.
constexpr double warn_relative_energy_error = 0.1;

std::string counts_text(const StatusCounts& counts) {
  std::string text = std::to_string(counts.completed) + " completed";
  const std::pair<const char*, std::size_t> others[] = {{"diverged", counts.diverged},
                                                        {"failed", counts.failed},
                                                        {"inaccurate", counts.inaccurate},
                                                        {"interrupted", counts.interrupted}};
  for (const auto& [name, count] : others)
    if (count > 0) text += ", " + std::to_string(count) + " " + name;
  return text;
}

bool ran_off(const RunOutcome& outcome, std::size_t trajectory) {
  return trajectory < outcome.runaways.size() && outcome.runaways[trajectory].has_value();
}

// One line per trajectory that stopped early, up to a screenful (an ensemble may have thousands; trajectories.csv
// has them all), and a warning when the energy error grew large.
void report_trajectories(const RunOutcome& outcome, const std::filesystem::path& directory) {
  constexpr std::size_t shown_at_most = 20;
  std::size_t stopped = 0;
  for (std::size_t index = 0; index < outcome.trajectories.size(); ++index) {
    const TrajectoryRecord& trajectory = outcome.trajectories[index];
    if (!stopped_early(trajectory.status) || ++stopped > shown_at_most) continue;
    if (trajectory.status == TrajectoryStatus::diverged)
      std::cerr << "nonsep: trajectory " << index << " diverged at step " << trajectory.stop_step
                << ", t = " << format_number(trajectory.stop_t) << " (" << trajectory.stop_variable << " is not finite)"
                << (ran_off(outcome, index) ? " after running off: " + runaway_text(*outcome.runaways[index]) : "")
                << "\n";
    else
      std::cerr << "nonsep: trajectory " << index << " " << to_string(trajectory.status) << ": " << trajectory.message
                << "\n";
  }
  if (stopped > shown_at_most)
    std::cerr << "nonsep: ... and " << stopped - shown_at_most << " more trajectories that stopped early; "
              << (directory / "trajectories.csv").string() << " lists them all\n";
  std::size_t ran_off_unreported = 0;  // ran off without diverging: a warning each, up to a few
  for (std::size_t index = 0; index < outcome.runaways.size(); ++index) {
    if (!ran_off(outcome, index) || outcome.trajectories[index].status == TrajectoryStatus::diverged) continue;
    if (++ran_off_unreported <= 3)
      std::cerr << "nonsep: warning: trajectory " << index << ": " << runaway_text(*outcome.runaways[index]) << "\n";
  }
  if (ran_off_unreported > 3)
    std::cerr << "nonsep: warning: ... and " << ran_off_unreported - 3 << " more trajectories ran off the same way\n";
  if (const auto& largest = outcome.largest_energy_error; largest && largest->value > warn_relative_energy_error)
    std::cerr << "nonsep: warning: the relative energy error |dH/H0| reached " << format_number(largest->value)
              << " (trajectory " << largest->trajectory << "), above " << format_number(warn_relative_energy_error)
              << ": the results are not accurate; "
              << (ran_off(outcome, largest->trajectory)
                      ? "that trajectory ran off with bounded energy first (above): the energy shell may be "
                        "non-compact, which a smaller dt or a higher order only delays\n"
                      : "use a smaller dt or a higher order (analysis.max_relative_energy_error stops trajectories "
                        "past a bound), or, if it does not shrink with dt, check the plugin's derivatives with "
                        "`nonsep inspect PLUGIN --check`\n");
}

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
  if (outcome->exit_status == ExitStatus::interrupted && stop_signal.load() != SIGINT)
    outcome->exit_status = ExitStatus::terminated;
  return outcome;
}

const char* signal_name(int signal) { return signal == SIGTERM ? "SIGTERM" : signal == SIGUSR1 ? "SIGUSR1" : "SIGINT"; }

int report_run(const RunOutcome& outcome, const Job& job, const RunArguments& arguments,
               const std::filesystem::path& directory, int signal) {
  const StatusCounts& c = outcome.counts;
  const std::size_t trajectories = c.completed + c.diverged + c.failed + c.inaccurate + c.interrupted;
  std::string line = std::string(to_string(outcome.status)) + ": " + std::to_string(trajectories) +
                     (trajectories == 1 ? " trajectory (" : " trajectories (") + counts_text(outcome.counts) + "), " +
                     time_text(job.run().time);
  if (const auto& largest = outcome.largest_energy_error)
    line += "; largest |dH/H0| " + format_number(largest->value) + " (trajectory " +
            std::to_string(largest->trajectory) + ")";
  line += "; results in " + directory.string();
  if (outcome.exit_status == ExitStatus::success) {
    if (!arguments.quiet) std::cout << line << "\n";
  } else {
    std::cerr << "nonsep: " << line << "\n";
    if (!outcome.error.empty()) std::cerr << "nonsep: " << outcome.error << "\n";
    if (outcome.status == TrajectoryStatus::interrupted && outcome.distributed)
      std::cerr << "nonsep: stopped by " << signal_name(signal) << "; `nonsep run " << arguments.job_file
                << (arguments.output.empty() ? "" : " --output " + arguments.output)
                << " --resume` continues the work units, with any number of MPI ranks\n";
    else if (outcome.status == TrajectoryStatus::interrupted)
      std::cerr << "nonsep: stopped by " << signal_name(signal) << " after step " << outcome.steps_completed
                << "; `nonsep run " << arguments.job_file
                << (arguments.output.empty() ? "" : " --output " + arguments.output)
                << " --resume` continues from there\n";
  }
  for (const std::string& note : outcome.notes)
    std::cerr << "nonsep: " << (note.starts_with("warning: ") ? "" : "note: ") << note << "\n";
  report_trajectories(outcome, directory);
  if (const std::size_t stopped = c.diverged + c.failed + c.inaccurate; outcome.distributed && stopped > 0)
    std::cerr << "nonsep: " << stopped << " trajectories stopped early; " << (directory / "trajectories.csv").string()
              << " says where and why\n";
  return to_int(outcome.exit_status);
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
    const int signal = stop_signal.load();
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
  return outcome ? report_run(*outcome, loaded.job, arguments, options.output_directory, stop_signal.load())
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
  options.stop_requested = &stop_requested;
  options.resume = arguments.resume;
  options.force = arguments.force;
  options.threads = arguments.threads;
  stop_requested.store(false);
  stop_signal.store(0);
  first_stop_nanoseconds.store(0);
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
      return outcome ? report_run(*outcome, loaded->job, arguments, options.output_directory, stop_signal.load())
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
        status = outcome ? report_run(*outcome, loaded->job, arguments, options.output_directory, stop_signal.load())
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
