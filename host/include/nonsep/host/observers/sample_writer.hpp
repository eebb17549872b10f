#pragma once
// trajectory.csv: the samples of every trajectory, streamed as the run goes. Header
//   trajectory,step,t,q0,...,q<n-1>,p0,...,p<n-1>,H,relative_energy_error
// One row per active trajectory at step 0, every `every`-th step and the last step, and one for each trajectory's
// final state where it stopped, unless that row is already there; so (step, trajectory) names a row, and the rows
// are in (step, trajectory) order (a chunk's rows wait in memory and are sorted before they are written). That
// order does not depend on how the ensemble is cut into blocks, chunks, threads or MPI ranks, which is what lets
// the files of ranks be merged into this one (cluster/merge_outputs.cpp). H and relative_energy_error are empty
// where H was not evaluated or H0 = 0. Flushed at least once a second. (An interrupted run may end with rows at
// its last step out of trajectory order: the rows of trajectories that stopped at that step are written by its
// checkpoint before the interrupted ones; a resume cuts them off.)
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

class SampleWriter : public Observer, public ChunkObserver, public CheckpointedObserver {
 public:
  static constexpr const char* file_name = "trajectory.csv";

  // The file at `path`, for `trajectories` states of `dimension` on `time` (which must outlive the writer): created
  // anew, or, when `resuming`, opened by restore(). Throws OutputError.
  SampleWriter(const std::filesystem::path& path, std::size_t dimension, std::size_t trajectories, std::uint64_t every,
               const TimeGrid& time, bool resuming);

  std::uint64_t next_event(std::uint64_t step) const override { return (step / every_ + 1) * every_; }
  bool needs_energy(std::uint64_t step) const override { return step % every_ == 0; }
  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;
  void after_chunk(std::uint64_t step) override;
  void on_end() override;

  std::string name() const override { return "trajectory_csv"; }
  // Flushes; the state is the file's size and the step of each trajectory's last row.
  nlohmann::json save() override;
  // Reopens the file cut back to the saved size. Throws OutputError, or CheckpointError when `state` is damaged.
  void restore(const nlohmann::json& state) override;

 private:
  void write_row(std::size_t trajectory, std::uint64_t step, std::span<const double> q, std::span<const double> p,
                 std::optional<double> energy, std::optional<double> energy_initial);

  // Writes the rows waiting in pending_ whose step is before `before`, in (step, trajectory) order.
  void write_pending(std::uint64_t before);

  struct PendingRow {
    std::uint64_t step;
    std::size_t trajectory;
    std::string text;  // without its '\n'
  };
  static constexpr std::uint64_t none = static_cast<std::uint64_t>(-1);
  std::filesystem::path path_;
  std::uint64_t every_, steps_;  // steps_: the last step, always sampled
  const TimeGrid& time_;
  std::optional<CsvAppender> file_;
  std::vector<PendingRow> pending_;
  std::vector<std::uint64_t> last_written_;  // per trajectory, `none` before its first row
  std::chrono::steady_clock::time_point next_flush_;
};

}  // namespace nonsep::host
