#pragma once
// One trajectory of an ensemble, as the driver knows it: how it ended and where. O(dimension) memory, whatever the
// number of steps. Observers keep anything else they track (energy errors, closest returns, ...) themselves.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace nonsep::host {

// Every status a trajectory (and, by the worst of its trajectories, a run) can have. The names are what
// trajectories.csv, summary.json, checkpoints and the console print.
enum class TrajectoryStatus {
  running,      // not finished yet (only inside a run and in checkpoints)
  completed,    // reached the last step
  diverged,     // q or p stopped being finite: stop_step, stop_variable
  failed,       // the plugin failed on it (or its energy could not be evaluated): message
  inaccurate,   // its relative energy error exceeded analysis.max_relative_energy_error: stop_step, message
  interrupted,  // the run was interrupted (SIGINT, SIGTERM) or failed as a whole before it finished
};

std::string_view to_string(TrajectoryStatus status);
// The status named `name`, or nothing.
std::optional<TrajectoryStatus> trajectory_status_from_string(std::string_view name);
// A trajectory that stopped early for a reason of its own (diverged, failed, inaccurate).
inline bool stopped_early(TrajectoryStatus status) {
  return status == TrajectoryStatus::diverged || status == TrajectoryStatus::failed ||
         status == TrajectoryStatus::inaccurate;
}

struct TrajectoryRecord {
  TrajectoryStatus status = TrajectoryStatus::running;
  // The final state: at the last step, where the run stopped, or the last finite state before it stopped early.
  std::uint64_t final_step = 0;
  double final_t = 0.0;
  std::vector<double> final_q, final_p;                // empty while running
  std::optional<double> energy_initial, energy_final;  // H at step 0 and of the final state, when known
  // Where it stopped early: the step at which the problem was found (for "diverged" the step whose result was not
  // finite, one after final_step), and what: the first non-finite variable ("q[0]", "p[1]") or the message.
  std::uint64_t stop_step = 0;
  double stop_t = 0.0;
  std::string stop_variable;
  std::string message;
  // The final values of the run's chaos indicators' columns (EnsembleSetup::indicators, in order), set when a run
  // that computes them retires the trajectory; empty for one that diverged or failed, and when not computed.
  std::vector<double> indicators;
};

// A trajectory that stops before the end of the run, and its record: the one record of a stopped trajectory, from
// the block that stops it to the files. An observer asks for a stop with the record's status and message
// (Event::retire, BlockView::retire); the block that holds the trajectory fills in the rest (the final state, where
// it stopped, the final estimates); the driver keeps the record, with the H0 it knows (EnsembleDriver::records), and
// shows it to every observer (Observer::on_retire); the run's files are written from the records.
struct StoppedTrajectory {
  std::size_t trajectory = 0;
  TrajectoryRecord record;
};

// An observer's request that `trajectory` stop with `status` and `message`.
inline StoppedTrajectory stop_request(std::size_t trajectory, TrajectoryStatus status, std::string message) {
  StoppedTrajectory stop{trajectory, {}};
  stop.record.status = status;
  stop.record.message = std::move(message);
  return stop;
}

// (H - H0) / H0, unknown when either is unknown or H0 = 0: trajectory.csv's and trajectories.csv's
// relative_energy_error.
inline std::optional<double> relative_energy_error(std::optional<double> energy, std::optional<double> initial) {
  if (!energy || !initial || *initial == 0.0) return std::nullopt;
  return (*energy - *initial) / *initial;
}

}  // namespace nonsep::host
