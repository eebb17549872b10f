#include "nonsep/host/observers/indicator_columns.hpp"

#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

IndicatorColumns::IndicatorColumns(const std::filesystem::path& path, const IndicatorList& indicators,
                                   std::uint64_t every, const std::vector<TrajectoryRecord>& records, bool resuming)
    : path_(path), every_(every), records_(records) {
  for (const auto& indicator : indicators)
    for (std::string& name : indicator->columns()) columns_.push_back(std::move(name));
  if (every_ == 0 || resuming) return;
  std::string header = "trajectory,step,t";
  for (const std::string& name : columns_) header += "," + name;
  file_.emplace(path, header);
}

std::uint64_t IndicatorColumns::next_event(std::uint64_t step) const {
  return every_ > 0 ? (step / every_ + 1) * every_ : no_event;
}

void IndicatorColumns::on_event(const Event& event) {
  if (every_ == 0 || event.step == 0 || event.step % every_ != 0) return;
  for (const StateView& state : event.states) {
    if (state.indicators.empty()) continue;
    std::string& row = file_->row();
    row += std::to_string(state.trajectory);
    row += ',';
    row += std::to_string(event.step);
    row += ',';
    append_number(row, event.t);
    append_values(row, state.indicators);
    file_->end_row();
  }
}

nlohmann::json IndicatorColumns::save() { return csv_checkpoint_state(*file_); }

void IndicatorColumns::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  resume_csv(file_, path_, state, [&](const std::string& what) { read.damaged(what); });
}

void IndicatorColumns::columns(std::vector<std::string>& names) const {
  names.insert(names.end(), columns_.begin(), columns_.end());
}

void IndicatorColumns::cells(std::size_t trajectory, std::string& row) const {
  append_values(row, records_[trajectory].indicators);
}

void IndicatorColumns::append_values(std::string& row, std::span<const double> values) const {
  for (std::size_t j = 0; j < columns_.size(); ++j) {
    row += ',';
    if (j < values.size()) append_number(row, values[j]);
  }
}

}  // namespace nonsep::host
