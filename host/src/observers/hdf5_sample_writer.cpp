#include "nonsep/host/observers/hdf5_sample_writer.hpp"

#include <algorithm>
#include <limits>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::uint64_t> Hdf5SampleWriter::sample_steps(std::uint64_t steps, std::uint64_t every) {
  std::vector<std::uint64_t> list;
  for (std::uint64_t step = 0; step <= steps; step += every) {
    list.push_back(step);
    if (steps - step < every) break;  // the next multiple would pass the end (or overflow)
  }
  if (list.back() != steps) list.push_back(steps);
  return list;
}

Hdf5SampleWriter::Hdf5SampleWriter(const std::filesystem::path& path, std::size_t dimension, std::size_t trajectories,
                                   std::uint64_t every, const TimeGrid& time, bool resuming)
    : path_(path), dimension_(dimension), every_(every), steps_(time.steps) {
  const std::vector<std::uint64_t> steps = sample_steps(time.steps, every);
  layout_ = {steps.size(), trajectories, dimension};
  if (resuming) return;
  std::vector<double> times;
  times.reserve(steps.size());
  for (std::uint64_t step : steps) times.push_back(time.time_at(step));
  file_.emplace(Hdf5File::create(path));
  datasets_.emplace(SampleDatasets::create(*file_, layout_, steps, times));
}

std::uint64_t Hdf5SampleWriter::row_of(std::uint64_t step) const {
  if (step % every_ == 0 && step <= steps_) return step / every_;
  return step == steps_ ? layout_.samples - 1 : none;
}

std::uint64_t Hdf5SampleWriter::group_rows() const {
  return std::min(datasets_->samples_per_chunk(), layout_.samples - group_first_);
}

void Hdf5SampleWriter::start_group_of(std::uint64_t row) {
  if (group_first_ != none && row >= group_first_ && row < group_first_ + group_rows()) return;
  if (unwritten_) write_group();
  group_first_ = row - row % datasets_->samples_per_chunk();
  const std::size_t cells = group_rows() * layout_.trajectories;
  q_.assign(cells * dimension_, nan);
  p_.assign(cells * dimension_, nan);
  H_.assign(cells, nan);
}

void Hdf5SampleWriter::write_group() {
  datasets_->write({.first_sample = group_first_,
                    .samples = group_rows(),
                    .first_trajectory = 0,
                    .trajectories = layout_.trajectories,
                    .q = q_,
                    .p = p_,
                    .H = H_});
  unwritten_ = false;
}

void Hdf5SampleWriter::put(std::uint64_t row, std::size_t trajectory, std::span<const double> q,
                           std::span<const double> p, std::optional<double> H) {
  start_group_of(row);
  const std::size_t cell = (row - group_first_) * layout_.trajectories + trajectory;
  std::copy(q.begin(), q.end(), q_.begin() + static_cast<std::ptrdiff_t>(cell * dimension_));
  std::copy(p.begin(), p.end(), p_.begin() + static_cast<std::ptrdiff_t>(cell * dimension_));
  H_[cell] = H.value_or(nan);
  unwritten_ = true;
}

void Hdf5SampleWriter::on_event(const Event& event) {
  const std::uint64_t row = row_of(event.step);
  if (row == none || row < rows_written_) return;  // not a sample, or written before a resume
  start_group_of(row);
  for (const StateView& state : event.states) put(row, state.trajectory, state.q, state.p, state.energy);
  unwritten_ = true;
  rows_written_ = row + 1;
  if (rows_written_ == group_first_ + group_rows()) write_group();
}

void Hdf5SampleWriter::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  // Only a stop exactly at the next sample step, which the event there will write; a stop at a sample already
  // written was written with it (the trajectory was active there), as trajectory.csv writes no second row.
  if (const std::uint64_t row = row_of(record.final_step); row != none && row >= rows_written_)
    put(row, trajectory, record.final_q, record.final_p, record.energy_final);
}

void Hdf5SampleWriter::on_end() {
  if (unwritten_) write_group();
  datasets_.reset();
  if (file_) file_->close();
  file_.reset();
}

nlohmann::json Hdf5SampleWriter::save() {
  // Checkpoints are taken after a chunk's events (checkpoint_saver.hpp), so no stopped trajectory waits in the
  // next row: everything the run has is in the file once the rows of an incomplete chunk are (with NaN after them,
  // until the chunk is written again whole).
  if (unwritten_) write_group();
  file_->flush();
  return {{"rows", rows_written_}};
}

void Hdf5SampleWriter::restore(const nlohmann::json& state) {
  const auto refuse = [&](const std::string& why) {
    throw CheckpointError("cannot resume into " + path_.string() + ": " + why + "; run with --force to start over");
  };
  const SavedState read = SavedState::of_observer(name(), state);
  const std::uint64_t saved_rows = read.count(read.member(state, "rows"), "rows", layout_.samples);
  try {
    file_.emplace(Hdf5File::open(path_));
    datasets_.emplace(SampleDatasets::open(*file_));
  } catch (const OutputError& error) {
    datasets_.reset();
    file_.reset();
    refuse(error.what());
  }
  if (!(datasets_->layout() == layout_))
    refuse("its /samples has " + std::to_string(datasets_->layout().samples) + " samples of " +
           std::to_string(datasets_->layout().trajectories) + " trajectories of dimension " +
           std::to_string(datasets_->layout().dimension) + ", the run " + std::to_string(layout_.samples) + " of " +
           std::to_string(layout_.trajectories) + " of dimension " + std::to_string(layout_.dimension));
  rows_written_ = saved_rows;
  if (rows_written_ == layout_.samples) return;
  // The rows of the incomplete chunk written before the checkpoint, which its next write must carry again.
  start_group_of(rows_written_);
  const std::uint64_t rows = rows_written_ - group_first_;
  const std::size_t cells = rows * layout_.trajectories;
  try {
    datasets_->read(group_first_, rows, std::span(q_).first(cells * dimension_),
                    std::span(p_).first(cells * dimension_), std::span(H_).first(cells));
  } catch (const OutputError& error) {
    refuse(error.what());
  }
}

}  // namespace nonsep::host
