#include "nonsep/host/observers/runaway.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/run/saved_state.hpp"

namespace nonsep::host {

namespace {

// max(|q_i|, |p_i|) over the components, leaving out each q_i whose momentum p_i is still exactly its initial value
// `p0_i`: a cyclic coordinate (H does not depend on it, so the schemes keep p_i to the bit), such as the time or an
// angle, grows without the orbit running off.
double scale_of(std::span<const double> q, std::span<const double> p, std::span<const double> p0) {
  double scale = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (p[i] != p0[i]) scale = std::max(scale, std::abs(q[i]));
    scale = std::max(scale, std::abs(p[i]));
  }
  return scale;
}

nlohmann::json number_or_null(const std::optional<double>& x) {
  return x ? nlohmann::json(format_number(*x)) : nlohmann::json();
}

}  // namespace

RunawayObserver::RunawayObserver(std::span<const double> q, std::span<const double> p, std::size_t count, std::size_t n,
                                 const TimeGrid& time)
    : reference_until_(std::abs(time.t_end) / 10.0),
      stride_(std::max<std::uint64_t>(1, time.steps / watched_steps)),
      n_(n),
      initial_p_(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(count * n)),
      watches_(count) {
  for (std::size_t b = 0; b < count; ++b) {
    // Every q_i counts at the start: a coordinate is taken for cyclic only once the steps have kept its momentum.
    double scale = 0.0;
    for (const auto x : {q.subspan(b * n, n), p.subspan(b * n, n)})
      for (double value : x) scale = std::max(scale, std::abs(value));
    watches_[b].reference_scale = scale;
  }
}

// The scale at t: into the reference in the first tenth, else into the furthest point.
void RunawayObserver::see_scale(std::size_t trajectory, double t, std::span<const double> q,
                                std::span<const double> p) {
  const double scale = scale_of(q, p, std::span<const double>(initial_p_).subspan(trajectory * n_, n_));
  if (!std::isfinite(scale)) return;  // a chunk that will be redone step by step (block_stepper.hpp)
  Watch& watch = watches_[trajectory];
  if (std::abs(t) <= reference_until_)
    watch.reference_scale = std::max(watch.reference_scale, scale);
  else if (!watch.furthest || scale > watch.furthest->scale)
    watch.furthest = Furthest{scale, t};
}

void RunawayObserver::see_energy(std::size_t trajectory, std::optional<double> energy,
                                 std::optional<double> energy_initial) {
  const auto error = relative_energy_error(energy, energy_initial);
  if (!error) return;
  Watch& watch = watches_[trajectory];
  watch.largest_error = std::max(watch.largest_error.value_or(0.0), std::abs(*error));
  const auto& furthest = watch.furthest;
  if (!(*watch.largest_error <= small_error) || !furthest || !(furthest->scale > growth * watch.reference_scale) ||
      (watch.runaway && furthest->scale <= watch.runaway->scale))
    return;
  watch.runaway = Runaway{watch.reference_scale, furthest->scale, furthest->t, *watch.largest_error};
}

// Only the events where H was evaluated: their steps are the job's (the others end chunks sized by the clock).
void RunawayObserver::on_event(const Event& event) {
  if (!event.energy_evaluated) return;
  for (const StateView& state : event.states) {
    see_scale(state.trajectory, event.t, state.q, state.p);
    see_energy(state.trajectory, state.energy, state.record->energy_initial);
  }
}

void RunawayObserver::on_retire(std::size_t trajectory, const TrajectoryRecord& record) {
  if (record.final_q.empty()) return;
  see_scale(trajectory, record.final_t, record.final_q, record.final_p);
  see_energy(trajectory, record.energy_final, record.energy_initial);
}

void RunawayObserver::on_step(std::uint64_t, double t, const BlockView& block) {
  const std::size_t n = block.dimension;
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
    see_scale(block.trajectories[slot], t, block.q.subspan(slot * n, n), block.p.subspan(slot * n, n));
}

void RunawayObserver::save_block(const BlockView& block) {
  auto& saved = saved_[block.block];
  saved.clear();
  for (std::size_t trajectory : block.trajectories) saved.push_back(watches_[trajectory]);
}

void RunawayObserver::restore_block(const BlockView& block) {
  const auto& saved = saved_[block.block];
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) watches_[block.trajectories[slot]] = saved[slot];
}

std::vector<std::optional<Runaway>> RunawayObserver::runaways() const {
  std::vector<std::optional<Runaway>> result;
  result.reserve(watches_.size());
  for (const Watch& watch : watches_) result.push_back(watch.runaway);
  return result;
}

// Per trajectory [reference scale, largest |dH/H0| or null, null or the furthest [scale, t], null or the runaway
// [reference, scale, t, largest error]].
nlohmann::json RunawayObserver::save() {
  nlohmann::json list = nlohmann::json::array();
  for (const Watch& watch : watches_) {
    nlohmann::json furthest, runaway;
    if (const auto& f = watch.furthest) furthest = {format_number(f->scale), format_number(f->t)};
    if (const auto& r = watch.runaway)
      runaway = {format_number(r->reference_scale), format_number(r->scale), format_number(r->t),
                 format_number(r->largest_error)};
    list.push_back({format_number(watch.reference_scale), number_or_null(watch.largest_error), std::move(furthest),
                    std::move(runaway)});
  }
  return {{"watches", std::move(list)}};
}

void RunawayObserver::restore(const nlohmann::json& state) {
  const SavedState read = SavedState::of_observer(name(), state);
  const nlohmann::json& list = read.list(read.member(state, "watches"), watches_.size(), "watches");
  for (std::size_t i = 0; i < watches_.size(); ++i) {
    const nlohmann::json& entry = read.list(list[i], 4, "watches");
    Watch& watch = watches_[i];
    watch.reference_scale = read.number(entry[0], "watches");
    watch.largest_error = read.optional_number(entry[1], "watches");
    watch.furthest.reset();
    if (!entry[2].is_null()) {
      const auto f = read.numbers(entry[2], 2, "watches");
      watch.furthest = Furthest{f[0], f[1]};
    }
    watch.runaway.reset();
    if (!entry[3].is_null()) {
      const auto r = read.numbers(entry[3], 4, "watches");
      watch.runaway = Runaway{r[0], r[1], r[2], r[3]};
    }
  }
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
