#pragma once
// Internal to the ensemble driver: a block of consecutive trajectories stepped together (one PhaseSpaceBatch, one
// Integrator), what it needs to redo a chunk, and the helpers that isolate one state's failure from the others.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/phase_space_batch.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/run/trajectory.hpp"
#include "run/tangent_block.hpp"

namespace nonsep::host {

// A trajectory that stops before the end of the run, as found by its block's worker, with its record filled in but
// H0 (trajectory.hpp). The driver retires them in (stop step, phase, trajectory) order, the order a step-by-step run
// finds them.
struct Departure {
  int phase = 0;  // 0: while stepping, 1: while evaluating H at the stop step, 2: asked by an observer
  StoppedTrajectory stopped;
};

// A stopped trajectory's final state (the state of `slot` in `x` at `step`, time `t`, with H `energy`) in `record`.
inline void record_final_state(TrajectoryRecord& record, const PhaseSpaceBatch& x, std::size_t slot, std::uint64_t step,
                               double t, std::optional<double> energy) {
  record.final_step = step;
  record.final_t = t;
  record.final_q.assign(x.q(slot).begin(), x.q(slot).end());
  record.final_p.assign(x.p(slot).begin(), x.p(slot).end());
  record.energy_final = energy;
}

// The first non-finite variable of state `slot` ("q[0]", "p[2]"), or "".
inline std::string first_non_finite(const PhaseSpaceBatch& x, std::size_t slot) {
  const auto q = x.q(slot), p = x.p(slot);
  for (std::size_t i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i])) return "q[" + std::to_string(i) + "]";
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!std::isfinite(p[i])) return "p[" + std::to_string(i) + "]";
  return "";
}

inline PhaseSpaceBatch single_state(const PhaseSpaceBatch& x, std::size_t slot) {
  return PhaseSpaceBatch::single(x.q(slot), x.p(slot));
}

inline void copy_state(const PhaseSpaceBatch& from, std::size_t from_slot, PhaseSpaceBatch& to, std::size_t to_slot) {
  const auto q = from.q(from_slot), p = from.p(from_slot);
  std::copy(q.begin(), q.end(), to.q(to_slot).begin());
  std::copy(p.begin(), p.end(), to.p(to_slot).begin());
}

// Runs `action` on the whole batch; when the model fails on it and the batch holds several states, reruns it state
// by state so that one failing state does not take the others down. `action(batch, first_slot)` works on a batch
// whose state 0 is slot `first_slot` of the original. Returns the model's message per slot ("" for success).
template <class Action>
std::vector<std::string> isolate_failures(PhaseSpaceBatch& x, const PhaseSpaceBatch& before, Action&& action) {
  std::vector<std::string> errors(x.count());
  try {
    action(x, 0);
    return errors;
  } catch (const ModelError& error) {
    if (x.count() == 1) {
      errors[0] = error.what();
      if (errors[0].empty()) errors[0] = "the model failed without a message";
      x = before;
      return errors;
    }
  }
  x = before;
  for (std::size_t slot = 0; slot < x.count(); ++slot) {
    PhaseSpaceBatch one = single_state(before, slot);
    try {
      action(one, slot);
      copy_state(one, 0, x, slot);
    } catch (const ModelError& error) {
      errors[slot] = error.what();
      if (errors[slot].empty()) errors[slot] = "the model failed without a message";
    }
  }
  return errors;
}

// Observers' stops in trajectory order, the order a step-by-step run applies them (Block::retire_requested).
inline void sort_requests(std::vector<StoppedTrajectory>& requests) {
  std::sort(requests.begin(), requests.end(),
            [](const StoppedTrajectory& a, const StoppedTrajectory& b) { return a.trajectory < b.trajectory; });
}

// Consecutive trajectories stepped together; the unit of work of a thread.
struct alignas(64) Block {  // a cache line of its own: threads count evaluations in neighbouring blocks
  PhaseSpaceBatch batch;
  std::vector<std::size_t> trajectories;  // slot in batch -> trajectory index
  Integrator integrator;
  std::vector<double> energies;  // per slot at energy_step (NaN when unknown)
  std::optional<std::uint64_t> energy_step;
  std::vector<Departure> departures;  // found in the current chunk
  PhaseSpaceBatch chunk_start;        // the block at the start of the current chunk
  std::optional<Integrator> chunk_start_integrator;
  std::optional<BlockTangents> tangents;  // when the run follows tangent vectors; then it steps the block
  std::optional<BlockTangents> chunk_start_tangents;
  std::vector<std::size_t> chunk_start_trajectories;
  std::vector<double> chunk_start_energies;
  std::size_t chunk_start_departures = 0;
  std::exception_ptr error;  // anything but a ModelError, thrown in the current chunk

  Block(const IntegratorSpec& spec, std::size_t dimension, std::span<const std::size_t> members,
        std::span<const double> q, std::span<const double> p)
      : batch(dimension, members.size()),
        trajectories(members.begin(), members.end()),
        integrator(spec),
        energies(members.size(), std::nan("")) {
    std::copy(q.begin(), q.end(), batch.q().begin());
    std::copy(p.begin(), p.end(), batch.p().begin());
  }

  bool empty() const { return trajectories.empty(); }

  // One step of the whole block (the driver's unchecked path).
  template <class M>
  void step(const M& model, double dt) {
    if (tangents)
      tangents->step(model, batch, dt);
    else
      integrator.step(model, batch, dt);
  }
  // `n` steps of the whole block, bit for bit n calls of step().
  template <class M>
  void step_n(const M& model, double dt, std::uint64_t n) {
    if (tangents)
      tangents->step_n(model, batch, dt, n);
    else
      integrator.step_n(model, batch, dt, n);
  }
  EvaluationCounts evaluations() const {
    return tangents ? tangents->integrator.evaluations() : integrator.evaluations();
  }
  // The private state of the scheme that steps the block (its tangent map's when it follows tangent vectors), and
  // what it reports.
  SchemeState save_scheme_state() const {
    return tangents ? tangents->integrator.save_state(batch) : integrator.save_state(batch);
  }
  void restore_scheme_state(const SchemeState& state) {
    if (tangents)
      tangents->integrator.restore_state(state);
    else
      integrator.restore_state(state);
  }
  std::vector<SchemeFigure> scheme_report() const {
    return tangents ? tangents->integrator.report() : integrator.report();
  }

  // The final values of the run's chaos indicators of `slot` into `record` (when computed).
  void final_estimates(std::size_t slot, TrajectoryRecord& record) const {
    if (!tangents) return;
    record.indicators.clear();
    tangents->values(slot, record.indicators);
  }
  void clear() { trajectories.clear(); }

  // H of `slot` at energy_step when it is finite.
  std::optional<double> energy(std::size_t slot) const {
    return std::isfinite(energies[slot]) ? std::optional<double>(energies[slot]) : std::nullopt;
  }

  bool all_finite() const {
    bool finite = true;
    for (double v : batch.q()) finite &= std::isfinite(v);
    for (double v : batch.p()) finite &= std::isfinite(v);
    return finite;
  }

  // Trajectories may leave the block inside a chunk (an every-step observer asks), so its members are saved too.
  void begin_chunk() {
    chunk_start = batch;
    chunk_start_integrator = integrator;
    chunk_start_tangents = tangents;
    chunk_start_trajectories = trajectories;
    chunk_start_energies = energies;
    chunk_start_departures = departures.size();
  }
  // Back to the chunk's start, to redo it step by step.
  void rollback_chunk() {
    batch = chunk_start;
    integrator = *chunk_start_integrator;
    tangents = chunk_start_tangents;
    trajectories = chunk_start_trajectories;
    energies = chunk_start_energies;
    departures.resize(chunk_start_departures);
  }
  // Back to the chunk's start for good: the run ends there.
  void abandon_chunk() {
    if (!chunk_start_integrator) return;
    rollback_chunk();
    departures.clear();
  }

  // Retires the trajectories of `requests` (sorted by trajectory; those not in this block are ignored) at `step`,
  // time `t`, phase 2, each with its request's status and message, its state there and H from `energy(slot)`.
  template <class Energy>
  void retire_requested(std::span<const StoppedTrajectory> requests, std::uint64_t step, double t, Energy&& energy) {
    std::vector<bool> retire(trajectories.size(), false);
    for (std::size_t slot = 0; slot < trajectories.size(); ++slot) {
      const auto found = std::lower_bound(
          requests.begin(), requests.end(), trajectories[slot],
          [](const StoppedTrajectory& r, std::size_t trajectory) { return r.trajectory < trajectory; });
      if (found == requests.end() || found->trajectory != trajectories[slot]) continue;
      retire[slot] = true;
      Departure departure{2, *found};
      TrajectoryRecord& record = departure.stopped.record;
      record.stop_step = step;
      record.stop_t = t;
      record_final_state(record, batch, slot, step, t, energy(slot));
      final_estimates(slot, record);
      departures.push_back(std::move(departure));
    }
    compact(retire);
  }

  // Removes the slots marked in `retire`, keeping the others in order.
  void compact(const std::vector<bool>& retire) {
    std::size_t kept = 0;
    for (bool r : retire) kept += r ? 0 : 1;
    if (kept == trajectories.size()) return;
    PhaseSpaceBatch next(batch.dimension(), kept);
    std::vector<std::size_t> next_trajectories;
    std::vector<double> next_energies;
    for (std::size_t slot = 0; slot < trajectories.size(); ++slot) {
      if (retire[slot]) continue;
      copy_state(batch, slot, next, next_trajectories.size());
      next_trajectories.push_back(trajectories[slot]);
      next_energies.push_back(energies[slot]);
    }
    batch = std::move(next);
    integrator.compact(retire);
    if (tangents) tangents->compact(retire);
    trajectories = std::move(next_trajectories);
    energies = std::move(next_energies);
  }
};

}  // namespace nonsep::host
