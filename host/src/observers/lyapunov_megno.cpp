#include "nonsep/host/observers/lyapunov_megno.hpp"

#include "nonsep/core/analysis/alignment_indices.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

LyapunovMegnoObserver::LyapunovMegnoObserver(const std::filesystem::path& path, const Analysis& analysis,
                                             const std::vector<TrajectoryRecord>& records, bool resuming)
    : path_(path),
      exponents_(analysis.lyapunov ? analysis.lyapunov->vectors : 0),
      megno_(analysis.megno),
      sali_(analysis.sali),
      gali_(analysis.gali),
      every_(analysis.lyapunov ? analysis.lyapunov->every : 0),
      records_(records) {
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
  std::vector<double> exponents(exponents_), gali;
  for (const StateView& state : event.states) {
    if (!state.lyapunov || !state.megno) continue;
    for (std::size_t j = 0; j < exponents_; ++j) exponents[j] = state.lyapunov->exponent(j);
    std::optional<double> sali;
    gali.clear();
    if (!state.alignment.empty()) {
      if (sali_) sali = AlignmentIndices::sali(state.alignment);
      for (std::size_t j = 2; j <= gali_; ++j) gali.push_back(AlignmentIndices::gali(state.alignment, j));
    }
    std::string& row = file_->row();
    row += std::to_string(state.trajectory);
    row += ',';
    row += std::to_string(event.step);
    row += ',';
    append_number(row, event.t);
    append_values(row, exponents, state.megno->y(), state.megno->mean_y(), sali, gali);
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
  if (sali_) names.push_back("sali");
  for (std::size_t j = 2; j <= gali_; ++j) names.push_back("gali" + std::to_string(j));
}

void LyapunovMegnoObserver::cells(std::size_t trajectory, std::string& row) const {
  const TrajectoryRecord& record = records_[trajectory];
  append_values(row, record.lyapunov, record.megno, record.mean_megno, record.sali, record.gali);
}

void LyapunovMegnoObserver::append_values(std::string& row, std::span<const double> exponents,
                                          std::optional<double> megno, std::optional<double> mean_megno,
                                          std::optional<double> sali, std::span<const double> gali) const {
  const auto cell = [&](std::span<const double> values, std::size_t j) {
    row += ',';
    if (j < values.size()) append_number(row, values[j]);
  };
  for (std::size_t j = 0; j < exponents_; ++j) cell(exponents, j);
  if (megno_) {
    row += ',';
    append_csv_number(row, megno);
    row += ',';
    append_csv_number(row, mean_megno);
  }
  if (sali_) {
    row += ',';
    append_csv_number(row, sali);
  }
  for (std::size_t j = 2; j <= gali_; ++j) cell(gali, j - 2);
}

}  // namespace nonsep::host
