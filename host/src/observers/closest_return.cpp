#include "nonsep/host/observers/closest_return.hpp"

#include <cmath>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

ClosestReturnObserver::ClosestReturnObserver(double after, std::size_t dimension, std::span<const double> q0,
                                             std::span<const double> p0)
    : after_(after), dimension_(dimension), q0_(q0), p0_(p0), closest_(q0.size() / dimension) {}

void ClosestReturnObserver::on_step(std::uint64_t step, double t, const BlockView& block) {
  if (std::abs(t) < std::abs(after_)) return;
  const std::size_t n = dimension_;
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    const std::size_t first = block.trajectories[slot] * n;
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dq = block.q[slot * n + i] - q0_[first + i];
      const double dp = block.p[slot * n + i] - p0_[first + i];
      sum += dq * dq + dp * dp;
    }
    const double distance = std::sqrt(sum);
    Closest& closest = closest_[block.trajectories[slot]];
    if (!closest.distance || distance < *closest.distance) closest = {distance, step, t};
  }
}

void ClosestReturnObserver::save_block(const BlockView& block) {
  auto& saved = saved_[block.block];
  saved.clear();
  for (std::size_t trajectory : block.trajectories) saved.push_back(closest_[trajectory]);
}

void ClosestReturnObserver::restore_block(const BlockView& block) {
  const auto& saved = saved_[block.block];
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) closest_[block.trajectories[slot]] = saved[slot];
}

nlohmann::json ClosestReturnObserver::save() {
  nlohmann::json list = nlohmann::json::array();
  for (const Closest& c : closest_)
    list.push_back(c.distance ? nlohmann::json{format_number(*c.distance), c.step, format_number(c.t)}
                              : nlohmann::json());
  return {{"closest", std::move(list)}};
}

void ClosestReturnObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& list = read.list(read.member(state, "closest"), closest_.size(), "closest");
  for (std::size_t i = 0; i < closest_.size(); ++i) {
    if (list[i].is_null()) {
      closest_[i] = {};
      continue;
    }
    const std::string what = "closest entry " + std::to_string(i);
    const nlohmann::json& entry = read.list(list[i], 3, what);
    const double distance = read.number(entry[0], what);
    if (!(distance >= 0.0)) read.damaged(what + " has a distance that is not >= 0");
    closest_[i] = {distance, read.count(entry[1], what), read.number(entry[2], what)};
  }
}

void ClosestReturnObserver::columns(std::vector<std::string>& names) const {
  names.insert(names.end(), {"closest_return_distance", "closest_return_t", "closest_return_step"});
}

void ClosestReturnObserver::cells(std::size_t trajectory, std::string& row) const {
  const Closest& c = closest_[trajectory];
  row += ',';
  append_csv_number(row, c.distance);
  row += ',';
  if (c.distance) append_number(row, c.t);
  row += ',';
  if (c.distance) row += std::to_string(c.step);
}

}  // namespace nonsep::host
