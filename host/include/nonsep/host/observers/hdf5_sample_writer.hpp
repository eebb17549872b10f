#pragma once
// results.h5's /samples (output.format "hdf5"; layout in output/hdf5_samples.hpp): the same samples as trajectory.csv
// (observers/sample_writer.hpp), as one row of every trajectory per sample step (step 0, every `every`-th step, the
// last step) written when the run reaches it. A trajectory that stopped before a sample has NaN there; one that
// stopped exactly at a sample step has its final state there, as trajectory.csv has its row. Final states of
// trajectories that stopped elsewhere are in /trajectories (added at the end of the run, output/results_h5.hpp).
//
// Rows are kept until they fill a chunk of /samples (one row when the ensemble fills a chunk, several for small
// ensembles: SampleDatasets::samples_per_chunk), so that every chunk is filtered and written once, whole.
//
// Checkpoints: save() writes the rows kept (an incomplete chunk, NaN after them) and everything cached to the file
// and records the number of rows written; restore() reopens the file, reads back the rows of the incomplete chunk,
// and the resumed run writes the later rows again with the same numbers. HDF5 1.10 keeps no journal:
// after a hard kill (SIGKILL, a crash) between checkpoints the file can be left unreadable, and --resume then
// refuses it, naming the file (a run stopped by SIGINT or SIGTERM closes it properly).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "nonsep/host/output/hdf5_samples.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

class Hdf5SampleWriter : public Observer, public CheckpointedObserver {
 public:
  static constexpr const char* file_name = "results.h5";

  // The file at `path`, for `trajectories` states of `dimension` on `time` (which must outlive the writer): created
  // anew with an empty /samples, or, when `resuming`, opened by restore(). Throws OutputError.
  Hdf5SampleWriter(const std::filesystem::path& path, std::size_t dimension, std::size_t trajectories,
                   std::uint64_t every, const TimeGrid& time, bool resuming);

  std::uint64_t next_event(std::uint64_t step) const override { return (step / every_ + 1) * every_; }
  bool needs_energy(std::uint64_t step) const override { return step % every_ == 0; }
  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;
  // Closes the file (run_job then adds the tables). Throws OutputError.
  void on_end() override;

  std::string name() const override { return "results_h5"; }
  // {"rows": the number of sample rows written}, after writing the cache out. Throws OutputError.
  nlohmann::json save() override;
  // Reopens the file and checks its /samples against the run. Throws CheckpointError naming the file.
  void restore(const nlohmann::json& state) override;

  // The sample steps of a run of `steps` steps sampled every `every` steps (every > 0).
  static std::vector<std::uint64_t> sample_steps(std::uint64_t steps, std::uint64_t every);

 private:
  static constexpr std::uint64_t none = static_cast<std::uint64_t>(-1);
  // The row of `step` in /samples, or `none` when it is not a sample step.
  std::uint64_t row_of(std::uint64_t step) const;
  // The rows of the group that starts at group_first_ (the samples of one chunk, fewer at the end).
  std::uint64_t group_rows() const;
  // Makes the group of `row` the one kept, writing the one kept before when it has unwritten rows.
  void start_group_of(std::uint64_t row);
  void write_group();
  void put(std::uint64_t row, std::size_t trajectory, std::span<const double> q, std::span<const double> p,
           std::optional<double> H);

  std::filesystem::path path_;
  std::size_t dimension_;
  std::uint64_t every_, steps_;
  SampleLayout layout_;
  std::optional<Hdf5File> file_;
  std::optional<SampleDatasets> datasets_;
  std::uint64_t rows_written_ = 0;
  // The rows of one chunk from group_first_, [rows][N][n] for q and p and [rows][N] for H, NaN where nothing was put:
  // filled by the events at their steps and by the trajectories that stopped exactly there before them (whose final
  // states the event no longer carries). unwritten_: put since the group was last written.
  std::uint64_t group_first_ = none;
  std::vector<double> q_, p_, H_;
  bool unwritten_ = false;
};

}  // namespace nonsep::host
