#pragma once
// checkpoint.json: everything a run needs to continue, bit for bit, after an interruption or a crash
// (`nonsep run JOB --resume`).
//
// A checkpoint is taken between two steps, after trajectory.csv has been flushed, and holds: the number of steps
// completed, the size of trajectory.csv at that moment (a resumed run cuts the file back to it, dropping rows
// written after the checkpoint, and appends), the active states in batch order with their energies, every
// trajectory's record (retired ones included: status, final state, energies, largest energy error so far), the
// evaluation counts, and a fingerprint of the job. Doubles are stored as shortest round-trip decimal strings
// ("0.1", "nan", "-inf"), so reading one back gives the same bits. The file is replaced atomically
// (write_file_atomically): a crash while saving leaves the previous checkpoint.
//
// The fingerprint covers what determines the numbers: plugin name and version, the model's parameters, the
// integrator, the initial states, the time grid, output.every and /analysis. It leaves out the output folder and the
// checkpoint policy, which may change between the interrupted run and the resumed one.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/core/model.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host {

// A checkpoint cannot be read, belongs to another job, or does not fit it. The message names the file and says
// what to do.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What the summary needs to know about one trajectory; O(dimension) memory, whatever the number of steps.
struct TrajectoryRecord {
  std::string status = "running";
  std::uint64_t final_step = 0;
  double final_t = 0.0;
  std::vector<double> final_q, final_p;
  std::optional<double> energy_initial, energy_final;
  double max_abs_relative_error = 0.0;
  std::optional<std::uint64_t> last_written_step;
  std::uint64_t diverged_step = 0;
  double diverged_t = 0.0;
  std::string diverged_variable;
  std::string error;
  // /analysis/closest_return_after: the smallest |(q, p) - (q0, p0)| from then on, where and when.
  std::optional<double> closest_distance;
  std::uint64_t closest_step = 0;
  double closest_t = 0.0;
};

// (H - H0) / H0, unknown when either is unknown or H0 = 0: trajectory.csv's relative_energy_error and the
// summary's relative_error_final.
inline std::optional<double> relative_energy_error(std::optional<double> energy, std::optional<double> initial) {
  if (!energy || !initial || *initial == 0.0) return std::nullopt;
  return (*energy - *initial) / *initial;
}

// The state of a run between two steps.
struct RunState {
  std::uint64_t step = 0;                 // steps completed
  std::uint64_t trajectory_bytes = 0;     // size of trajectory.csv after step `step` (0 when there is none)
  std::vector<std::size_t> slots;         // the active trajectories, in batch order
  std::vector<double> q, p;               // their states, state-major (slot s at s * dimension)
  std::vector<double> energies;           // their energies at `step` (NaN when unknown)
  std::vector<TrajectoryRecord> records;  // every trajectory, by index
  EvaluationCounts evaluations;           // gradient evaluations so far
};

// 16 hexadecimal digits (FNV-1a, 64 bits) identifying the job's numbers, as described above.
std::string job_fingerprint(const LoadedJob& job);

// The file name inside a run's output folder.
inline constexpr const char* checkpoint_file_name = "checkpoint.json";

// Writes `state` to `path` atomically. Throws OutputError.
void save_checkpoint(const std::filesystem::path& path, const RunState& state, const std::string& fingerprint);

// Reads the checkpoint at `path` and checks it against the job (fingerprint, number of trajectories, dimension,
// steps). Throws CheckpointError.
RunState load_checkpoint(const std::filesystem::path& path, const LoadedJob& job);

}  // namespace nonsep::host
