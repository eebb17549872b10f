#include "nonsep/host/run/trajectory.hpp"

#include <array>
#include <utility>

namespace nonsep::host {

namespace {
constexpr std::array<std::pair<TrajectoryStatus, std::string_view>, 6> names{{
    {TrajectoryStatus::running, "running"},
    {TrajectoryStatus::completed, "completed"},
    {TrajectoryStatus::diverged, "diverged"},
    {TrajectoryStatus::failed, "failed"},
    {TrajectoryStatus::inaccurate, "inaccurate"},
    {TrajectoryStatus::interrupted, "interrupted"},
}};
}  // namespace

std::string_view to_string(TrajectoryStatus status) {
  for (const auto& [value, name] : names)
    if (value == status) return name;
  return "unknown";
}

std::optional<TrajectoryStatus> trajectory_status_from_string(std::string_view name) {
  for (const auto& [value, text] : names)
    if (text == name) return value;
  return std::nullopt;
}

}  // namespace nonsep::host
