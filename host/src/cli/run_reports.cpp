// What `nonsep run` says at the end (run_reports.hpp).
#include "cli/run_reports.hpp"

#include <cmath>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "cli/stop_signals.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::cli {

namespace {

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

}  // namespace

int report_study(const StudyOutcome& outcome, const std::filesystem::path& directory, bool quiet) {
  const StatusCounts& runs = outcome.run_counts;
  std::string line = std::string(to_string(outcome.status)) + ": study of " +
                     counted(outcome.fits.size(), "integrator") + ", " + counted(runs.completed, "run") + " completed";
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

}  // namespace nonsep::host::cli
