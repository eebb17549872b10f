#include "nonsep/host/observers/error_estimate.hpp"

#include <algorithm>
#include <cmath>

#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

double richardson_factor(double order) { return 1.0 / (1.0 - std::pow(2.0, -order)); }

std::vector<std::uint64_t> error_estimate_steps(std::uint64_t steps, std::uint64_t every) {
  const std::uint64_t stride =
      every > 0 ? every : std::max<std::uint64_t>(1, (steps + error_estimate_points - 1) / error_estimate_points);
  std::vector<std::uint64_t> list;
  for (std::uint64_t k = stride; k < steps; k += stride) list.push_back(k);
  list.push_back(steps);
  return list;
}

namespace {

double length(std::span<const double> q, std::span<const double> p) {
  double sum = 0.0;
  for (const double x : q) sum += x * x;
  for (const double x : p) sum += x * x;
  return std::sqrt(sum);
}

}  // namespace

FineRun::FineRun(std::size_t trajectories, std::size_t dimension, std::vector<std::uint64_t> coarse_steps)
    : dimension_(dimension),
      coarse_steps_(std::move(coarse_steps)),
      states_(trajectories * coarse_steps_.size() * (2 * dimension + 2), std::nan("")),
      recorded_(trajectories * coarse_steps_.size(), 0),
      stopped_(trajectories) {}

std::optional<std::size_t> FineRun::index_of(std::uint64_t fine_step) const {
  if (fine_step % 2 != 0) return std::nullopt;
  const auto at = std::lower_bound(coarse_steps_.begin(), coarse_steps_.end(), fine_step / 2);
  if (at == coarse_steps_.end() || *at != fine_step / 2) return std::nullopt;
  return static_cast<std::size_t>(at - coarse_steps_.begin());
}

std::uint64_t FineRun::next_event(std::uint64_t step) const {
  const auto at = std::upper_bound(coarse_steps_.begin(), coarse_steps_.end(), step / 2);
  return at == coarse_steps_.end() ? no_event : 2 * *at;
}

// Each record: q (n), p (n), H, |(q, p)(0)|.
void FineRun::on_event(const Event& event) {
  const std::size_t width = 2 * dimension_ + 2;
  if (event.step == 0) {
    for (const StateView& state : event.states)
      for (std::size_t point = 0; point < coarse_steps_.size(); ++point)
        states_[(state.trajectory * coarse_steps_.size() + point) * width + 2 * dimension_ + 1] =
            length(state.q, state.p);
    return;
  }
  const auto point = index_of(event.step);
  if (!point) return;
  for (const StateView& state : event.states) {
    double* record = &states_[(state.trajectory * coarse_steps_.size() + *point) * width];
    std::copy(state.q.begin(), state.q.end(), record);
    std::copy(state.p.begin(), state.p.end(), record + dimension_);
    record[2 * dimension_] = state.energy.value_or(std::nan(""));
    recorded_[state.trajectory * coarse_steps_.size() + *point] = 1;
  }
}

void FineRun::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  if (!stopped_early(record.status)) return;
  stopped_[trajectory] = std::string(to_string(record.status)) + " at step " + std::to_string(record.stop_step) +
                         (record.status == TrajectoryStatus::diverged ? " (" + record.stop_variable + " not finite)"
                                                                      : ": " + record.message);
}

std::optional<std::span<const double>> FineRun::state(std::size_t trajectory, std::size_t point) const {
  if (!recorded_[trajectory * coarse_steps_.size() + point]) return std::nullopt;
  return std::span<const double>(&states_[(trajectory * coarse_steps_.size() + point) * (2 * dimension_ + 2)],
                                 2 * dimension_);
}

double FineRun::energy(std::size_t trajectory, std::size_t point) const {
  return states_[(trajectory * coarse_steps_.size() + point) * (2 * dimension_ + 2) + 2 * dimension_];
}

ErrorEstimateObserver::ErrorEstimateObserver(const std::filesystem::path& path, FineRun fine, double order,
                                             std::size_t dimension, bool resuming)
    : path_(path),
      fine_(std::move(fine)),
      factor_(richardson_factor(order)),
      dimension_(dimension),
      estimates_(fine_.trajectories()) {
  if (!resuming)
    file_.emplace(path, "trajectory,step,t,estimated_phase_error,estimated_relative_energy_error,separated");
}

double FineRun::initial_length(std::size_t trajectory) const {
  return states_[trajectory * coarse_steps_.size() * (2 * dimension_ + 2) + 2 * dimension_ + 1];
}

std::uint64_t ErrorEstimateObserver::next_event(std::uint64_t step) const {
  const auto& steps = fine_.coarse_steps();
  const auto at = std::upper_bound(steps.begin(), steps.end(), step);
  return at == steps.end() ? no_event : *at;
}

bool ErrorEstimateObserver::needs_energy(std::uint64_t step) const {
  const auto& steps = fine_.coarse_steps();
  return std::binary_search(steps.begin(), steps.end(), step);
}

void ErrorEstimateObserver::on_event(const Event& event) {
  const auto& steps = fine_.coarse_steps();
  const auto at = std::lower_bound(steps.begin(), steps.end(), event.step);
  if (event.step == 0 || at == steps.end() || *at != event.step) return;
  const auto point = static_cast<std::size_t>(at - steps.begin());
  for (const StateView& state : event.states) {
    Estimate& estimate = estimates_[state.trajectory];
    const auto fine = fine_.state(state.trajectory, point);
    estimate.t = event.t;
    if (!fine) {
      estimate.unavailable = true;
      estimate.phase.reset();
      estimate.energy.reset();
    } else {
      double sum = 0.0;
      for (std::size_t i = 0; i < dimension_; ++i) {
        const double dq = state.q[i] - (*fine)[i], dp = state.p[i] - (*fine)[dimension_ + i];
        sum += dq * dq + dp * dp;
      }
      estimate.phase = factor_ * std::sqrt(sum);
      const double h0 = state.record->energy_initial.value_or(std::nan(""));
      const double h_fine = fine_.energy(state.trajectory, point);
      estimate.energy.reset();
      if (state.energy && std::isfinite(h_fine) && h0 != 0.0 && std::isfinite(h0))
        estimate.energy = factor_ * (*state.energy - h_fine) / h0;
      const double scale = std::max(length(state.q, state.p), fine_.initial_length(state.trajectory));
      if (!estimate.horizon && !(*estimate.phase <= error_estimate_separation * scale)) estimate.horizon = event.t;
    }
    std::string& row = file_->row();
    row += std::to_string(state.trajectory) + "," + std::to_string(event.step) + ",";
    append_number(row, event.t);
    row += ',';
    append_csv_number(row, estimate.phase);
    row += ',';
    append_csv_number(row, estimate.energy);
    row += fine ? (estimate.horizon ? ",true" : ",false") : ",";
    file_->end_row();
  }
}

nlohmann::json ErrorEstimateObserver::save() {
  nlohmann::json state = csv_checkpoint_state(*file_);
  nlohmann::json values = nlohmann::json::array();
  const auto text = [](const std::optional<double>& x) { return x ? nlohmann::json(format_number(*x)) : nullptr; };
  for (const Estimate& e : estimates_)
    values.push_back({text(e.phase), text(e.energy), text(e.t), text(e.horizon), e.unavailable});
  state["estimates"] = std::move(values);
  return state;
}

void ErrorEstimateObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& values = read.list(read.member(state, "estimates"), estimates_.size(), "estimates");
  for (std::size_t i = 0; i < estimates_.size(); ++i) {
    const nlohmann::json& entry = read.list(values[i], 5, "estimates[" + std::to_string(i) + "]");
    Estimate& e = estimates_[i];
    e.phase = read.optional_number(entry[0], "estimates");
    e.energy = read.optional_number(entry[1], "estimates");
    e.t = read.optional_number(entry[2], "estimates");
    e.horizon = read.optional_number(entry[3], "estimates");
    if (!entry[4].is_boolean()) read.damaged("estimates[" + std::to_string(i) + "] has no flag");
    e.unavailable = entry[4].get<bool>();
  }
  resume_csv(file_, path_, state, [&](const std::string& what) { read.damaged(what); });
}

void ErrorEstimateObserver::columns(std::vector<std::string>& names) const {
  names.insert(names.end(), {"estimated_phase_error", "estimated_relative_energy_error", "error_estimate_t",
                             "error_estimate_horizon", "error_estimate"});
}

void ErrorEstimateObserver::cells(std::size_t trajectory, std::string& row) const {
  const Estimate& e = estimates_[trajectory];
  for (const auto& value : {e.phase, e.energy, e.t, e.horizon}) {
    row += ',';
    append_csv_number(row, value);
  }
  row += e.unavailable ? ",unavailable" : e.horizon ? ",separated" : e.t ? ",within_horizon" : ",";
}

ErrorEstimateObserver::Totals ErrorEstimateObserver::totals() const {
  Totals totals;
  const auto larger = [](std::optional<double>& into, const std::optional<double>& value) {
    if (value && (!into || std::abs(*value) > *into)) into = std::abs(*value);
  };
  for (const Estimate& e : estimates_) {
    if (e.unavailable) ++totals.unavailable;
    if (e.horizon) {
      ++totals.separated;
      if (!totals.earliest_horizon || std::abs(*e.horizon) < std::abs(*totals.earliest_horizon))
        totals.earliest_horizon = e.horizon;
    }
    larger(totals.largest_phase_error, e.phase);
    larger(totals.largest_energy_error, e.energy);
  }
  return totals;
}

}  // namespace nonsep::host
