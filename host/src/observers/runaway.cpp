#include "nonsep/host/observers/runaway.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nonsep::host {

namespace {

double scale_of(std::span<const double> q, std::span<const double> p) {
  double scale = 0.0;
  for (const auto* x : {&q, &p})
    for (double value : *x) scale = std::max(scale, std::abs(value));
  return scale;
}

}  // namespace

RunawayObserver::RunawayObserver(std::span<const double> q, std::span<const double> p, std::size_t count, std::size_t n,
                                 double t_end)
    : reference_until_(std::abs(t_end) / 10.0), reference_scale_(count), largest_error_(count, 0.0), runaways_(count) {
  for (std::size_t b = 0; b < count; ++b) reference_scale_[b] = scale_of(q.subspan(b * n, n), p.subspan(b * n, n));
}

void RunawayObserver::see(std::size_t trajectory, double t, std::span<const double> q, std::span<const double> p,
                          std::optional<double> energy, std::optional<double> energy_initial) {
  const auto error = relative_energy_error(energy, energy_initial);
  if (!error) return;
  double& largest = largest_error_[trajectory];
  largest = std::max(largest, std::abs(*error));
  const double scale = scale_of(q, p);
  double& reference = reference_scale_[trajectory];
  if (std::abs(t) <= reference_until_) {
    reference = std::max(reference, scale);
    return;
  }
  auto& runaway = runaways_[trajectory];
  if (!(largest <= small_error) || !(scale > growth * reference) || (runaway && scale <= runaway->scale)) return;
  runaway = Runaway{reference, scale, t, largest};
}

void RunawayObserver::on_event(const Event& event) {
  if (!event.energy_evaluated) return;
  for (const StateView& state : event.states)
    see(state.trajectory, event.t, state.q, state.p, state.energy, state.record->energy_initial);
}

void RunawayObserver::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  if (!record.final_q.empty())
    see(trajectory, record.final_t, record.final_q, record.final_p, record.energy_final, record.energy_initial);
}

std::string runaway_text(const Runaway& runaway) {
  const auto text = [](double value) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", value);
    return std::string(buffer);
  };
  return "max(|q_i|, |p_i|) grew from " + text(runaway.reference_scale) +
         " (its largest in the first tenth of the run) to " + text(runaway.scale) + " by t = " + text(runaway.t) +
         " while |dH/H0| stayed at most " + text(runaway.largest_error) +
         ": the orbit runs off with bounded energy, so the energy shell may be non-compact (docs/method.md, "
         "\"Non-compact energy shells\"): errors along a direction in which H stays flat are never pulled back; a "
         "smaller dt or a higher order only delays the escape, a T and V whose H grows in every direction removes it";
}

}  // namespace nonsep::host
