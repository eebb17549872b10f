#include "nonsep/host/observers/sample_writer.hpp"

#include <algorithm>
#include <tuple>

#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

SampleWriter::SampleWriter(const std::filesystem::path& path, std::size_t dimension, std::size_t trajectories,
                           std::uint64_t every, const TimeGrid& time, bool resuming)
    : path_(path),
      every_(every),
      steps_(time.steps),
      time_(time),
      last_written_(trajectories, none),
      next_flush_(std::chrono::steady_clock::now() + std::chrono::seconds(1)) {
  std::string header = "trajectory,step,t";
  for (const char* name : {"q", "p"})
    for (std::size_t i = 0; i < dimension; ++i) {
      header += ',';
      header += name;
      header += std::to_string(i);
    }
  header += ",H,relative_energy_error";
  if (!resuming) file_.emplace(path, header);
}

void SampleWriter::write_row(std::size_t trajectory, std::uint64_t step, std::span<const double> q,
                             std::span<const double> p, std::optional<double> energy,
                             std::optional<double> energy_initial) {
  if (last_written_[trajectory] == step) return;
  PendingRow& pending = pending_.emplace_back(PendingRow{step, trajectory, {}});
  std::string& row = pending.text;
  row += std::to_string(trajectory);
  row += ',';
  row += std::to_string(step);
  row += ',';
  append_number(row, time_.time_at(step));
  for (double x : q) {
    row += ',';
    append_number(row, x);
  }
  for (double x : p) {
    row += ',';
    append_number(row, x);
  }
  row += ',';
  append_csv_number(row, energy);
  row += ',';
  append_csv_number(row, relative_energy_error(energy, energy_initial));
  last_written_[trajectory] = step;
}

void SampleWriter::write_pending(std::uint64_t before) {
  std::stable_sort(pending_.begin(), pending_.end(), [](const PendingRow& a, const PendingRow& b) {
    return std::tie(a.step, a.trajectory) < std::tie(b.step, b.trajectory);
  });
  std::size_t written = 0;
  for (; written < pending_.size() && pending_[written].step < before; ++written) {
    file_->row() += pending_[written].text;
    file_->end_row();
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(written));
}

void SampleWriter::on_event(const Event& event) {
  if (event.step % every_ != 0 && event.step != steps_) return;
  for (const StateView& state : event.states)
    write_row(state.trajectory, event.step, state.q, state.p, state.energy, state.record->energy_initial);
}

void SampleWriter::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  write_row(trajectory, record.final_step, record.final_q, record.final_p, record.energy_final, record.energy_initial);
}

void SampleWriter::after_chunk(std::uint64_t step) {
  write_pending(step);  // rows at `step` itself wait: a trajectory stopping there at the end may still add one
  const auto now = std::chrono::steady_clock::now();
  if (now < next_flush_) return;
  file_->flush();
  next_flush_ = now + std::chrono::seconds(1);
}

void SampleWriter::on_end() {
  write_pending(none);
  file_->flush();
}

nlohmann::json SampleWriter::save() {
  write_pending(none);
  nlohmann::json last = nlohmann::json::array();
  for (std::uint64_t step : last_written_)
    last.push_back(step == none ? nlohmann::json(nullptr) : nlohmann::json(step));
  nlohmann::json state = csv_checkpoint_state(*file_);
  state["last_written_step"] = std::move(last);
  return state;
}

void SampleWriter::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& last =
      read.list(read.member(state, "last_written_step"), last_written_.size(), "last_written_step");
  for (std::size_t i = 0; i < last.size(); ++i)
    last_written_[i] = last[i].is_null() ? none : read.count(last[i], "a last row's step", steps_);
  resume_csv(file_, path_, state, [&](const std::string& what) { read.damaged(what); });
}

}  // namespace nonsep::host
