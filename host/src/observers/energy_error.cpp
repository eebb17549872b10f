#include "nonsep/host/observers/energy_error.hpp"

#include <cmath>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

EnergyErrorObserver::EnergyErrorObserver(std::size_t trajectories, std::uint64_t energy_every,
                                         std::optional<double> bound)
    : energy_every_(energy_every), bound_(bound), max_abs_(trajectories) {}

std::uint64_t EnergyErrorObserver::next_event(std::uint64_t step) const {
  return energy_every_ > 0 ? (step / energy_every_ + 1) * energy_every_ : no_event;
}

std::optional<double> EnergyErrorObserver::include(std::size_t trajectory, std::optional<double> energy,
                                                   std::optional<double> energy_initial) {
  const auto error = relative_energy_error(energy, energy_initial);
  if (!error) return std::nullopt;
  auto& max = max_abs_[trajectory];
  max = std::max(max.value_or(0.0), std::abs(*error));
  return error;
}

void EnergyErrorObserver::on_event(const Event& event) {
  if (!event.energy_evaluated) return;
  if (event.step > 0) evaluated_after_start_ = true;
  for (const StateView& state : event.states) {
    if (!state.energy) continue;
    const auto error = include(state.trajectory, state.energy, state.record->energy_initial);
    if (!error) continue;
    if (bound_ && !(std::abs(*error) <= *bound_))
      event.retire->push_back(
          stop_request(state.trajectory, TrajectoryStatus::inaccurate,
                       "the relative energy error " + format_number(*error) + " at step " + std::to_string(event.step) +
                           " exceeds analysis.max_relative_energy_error = " + format_number(*bound_)));
  }
}

void EnergyErrorObserver::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  include(trajectory, record.energy_final, record.energy_initial);
}

std::optional<LargestEnergyError> EnergyErrorObserver::largest() const {
  std::optional<LargestEnergyError> result;
  for (std::size_t i = 0; i < max_abs_.size(); ++i)
    if (max_abs_[i] && (!result || *max_abs_[i] > result->value)) result = LargestEnergyError{*max_abs_[i], i};
  return result;
}

nlohmann::json EnergyErrorObserver::save() {
  nlohmann::json values = nlohmann::json::array();
  for (const auto& max : max_abs_) values.push_back(max ? nlohmann::json(format_number(*max)) : nlohmann::json());
  return {{"max_abs", std::move(values)}, {"evaluated_after_start", std::uint64_t{evaluated_after_start_ ? 1u : 0u}}};
}

void EnergyErrorObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& values = read.list(read.member(state, "max_abs"), max_abs_.size(), "max_abs");
  for (std::size_t i = 0; i < max_abs_.size(); ++i) {
    max_abs_[i] = read.optional_number(values[i], "max_abs");
    if (max_abs_[i] && !(*max_abs_[i] >= 0.0)) read.damaged("max_abs is not a number >= 0");
  }
  evaluated_after_start_ = read.count(read.member(state, "evaluated_after_start"), "evaluated_after_start", 1) == 1;
}

void EnergyErrorObserver::columns(std::vector<std::string>& names) const {
  names.push_back("max_abs_relative_energy_error");
}

void EnergyErrorObserver::cells(std::size_t trajectory, std::string& row) const {
  row += ',';
  append_csv_number(row, max_abs_[trajectory]);
}

}  // namespace nonsep::host
