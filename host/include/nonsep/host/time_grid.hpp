#pragma once
// The time grid of a run, and the one rule that turns an end time and a step size into a number of steps.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

namespace nonsep::host {

// Largest accepted number of steps; larger values are reported as out of range.
inline constexpr std::uint64_t max_steps = 1'000'000'000'000;

// The number of steps of about `dt` that end exactly at `t_end`: ceil(r (1 - 1e-9)) for r = t_end / dt, at least 1
// (the slack keeps a t_end that is a whole number of steps up to rounding from gaining a tiny extra step). As a
// double, so that a caller can report a count beyond max_steps; nothing when t_end / dt is not positive and finite.
inline std::optional<double> steps_to_reach(double t_end, double dt) {
  const double ratio = t_end / dt;
  if (!(ratio > 0.0) || !std::isfinite(ratio)) return std::nullopt;
  return std::max(1.0, std::ceil(ratio * (1.0 - 1e-9)));
}

// t_k = k * dt for k < steps, and t_steps = t_end exactly.
// From an end time (TimeGrid::to_end): steps = steps_to_reach(t_end, dt_requested) and dt = t_end / steps, so the
// run ends exactly at t_end with |dt| <= |dt_requested|. From a step count (TimeGrid::of_steps): dt = dt_requested
// and t_end = steps * dt.
struct TimeGrid {
  double dt_requested = 0.0;
  double dt = 0.0;
  std::uint64_t steps = 0;
  double t_end = 0.0;
  bool from_t_end = false;

  double time_at(std::uint64_t step) const { return step == steps ? t_end : static_cast<double>(step) * dt; }

  // `steps` must be steps_to_reach(t_end, dt_requested) (checked by the caller against max_steps).
  static TimeGrid to_end(double t_end, double dt_requested, std::uint64_t steps) {
    return {dt_requested, t_end / static_cast<double>(steps), steps, t_end, true};
  }
  static TimeGrid of_steps(std::uint64_t steps, double dt) {
    return {dt, dt, steps, static_cast<double>(steps) * dt, false};
  }

  // The same run with every step cut into m: m times the steps, of dt / m (and dt_requested / m), ending where this
  // one ends. For /analysis/error_estimate's run with half the step (m = 2) and the step that scheme auto chose.
  TimeGrid subdivided(std::uint64_t m) const {
    const double parts = static_cast<double>(m);
    return from_t_end ? to_end(t_end, dt_requested / parts, steps * m) : of_steps(steps * m, dt / parts);
  }
};

}  // namespace nonsep::host
