#include "nonsep/host/observers/lyapunov_megno.hpp"

#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

LyapunovMegnoObserver::LyapunovMegnoObserver(const std::filesystem::path& path, std::size_t exponents, bool megno,
                                             std::uint64_t every, const std::vector<TrajectoryRecord>& records,
                                             bool resuming)
    : path_(path), exponents_(exponents), megno_(megno), every_(every), records_(records) {
  if (every_ == 0 || resuming) return;
  std::string header = "trajectory,step,t";
  std::vector<std::string> names;
  columns(names);
  for (const std::string& name : names) header += "," + name;
  file_.emplace(path, header);
}

std::uint64_t LyapunovMegnoObserver::next_event(std::uint64_t step) const {
  return every_ > 0 ? (step / every_ + 1) * every_ : no_event;
}

void LyapunovMegnoObserver::on_event(const Event& event) {
  if (every_ == 0 || event.step == 0 || event.step % every_ != 0) return;
  for (const StateView& state : event.states) {
    if (!state.lyapunov || !state.megno) continue;
    std::string& row = file_->row();
    row += std::to_string(state.trajectory);
    row += ',';
    row += std::to_string(event.step);
    row += ',';
    append_number(row, event.t);
    for (std::size_t j = 0; j < exponents_; ++j) {
      row += ',';
      append_number(row, state.lyapunov->exponent(j));
    }
    if (megno_) {
      row += ',';
      append_number(row, state.megno->y());
      row += ',';
      append_number(row, state.megno->mean_y());
    }
    file_->end_row();
  }
}

nlohmann::json LyapunovMegnoObserver::save() { return csv_checkpoint_state(*file_); }

void LyapunovMegnoObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  resume_csv(file_, path_, state, [&](const std::string& what) { read.damaged(what); });
}

void LyapunovMegnoObserver::columns(std::vector<std::string>& names) const {
  for (std::size_t j = 0; j < exponents_; ++j) names.push_back("lyapunov" + std::to_string(j));
  if (megno_) names.insert(names.end(), {"megno", "mean_megno"});
}

void LyapunovMegnoObserver::cells(std::size_t trajectory, std::string& row) const {
  const TrajectoryRecord& record = records_[trajectory];
  for (std::size_t j = 0; j < exponents_; ++j) {
    row += ',';
    if (j < record.lyapunov.size()) append_number(row, record.lyapunov[j]);
  }
  if (megno_) {
    row += ',';
    append_csv_number(row, record.megno);
    row += ',';
    append_csv_number(row, record.mean_megno);
  }
}

}  // namespace nonsep::host
