#include "run/block_stepper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "nonsep/core/base/error.hpp"

namespace nonsep::host {

BlockView BlockStepper::view(const Block& block, std::size_t index, const Worker& worker) const {
  return {index, dimension, block.trajectories, block.batch.q(), block.batch.p(), &worker.model};
}

bool BlockStepper::every_step() const {
  return std::any_of(step_watchers.begin(), step_watchers.end(), [](StepObserver* w) { return w->stride() == 0; });
}

std::uint64_t BlockStepper::next_watched(std::uint64_t step) const {
  std::uint64_t next = std::numeric_limits<std::uint64_t>::max();
  for (StepObserver* watcher : step_watchers) {
    const std::uint64_t stride = std::max<std::uint64_t>(1, watcher->stride());
    next = std::min(next, (step / stride + 1) * stride);
  }
  return next;
}

// The observers that watch `step` see the block there; the trajectories they ask to stop leave it there.
void BlockStepper::watch_step(Block& block, std::size_t index, Worker& worker, std::uint64_t step) {
  if (step_watchers.empty()) return;
  std::vector<StoppedTrajectory> requests;
  auto v = view(block, index, worker);
  v.retire = &requests;
  for (StepObserver* watcher : step_watchers)
    if (watcher->stride() == 0 || step % watcher->stride() == 0) watcher->on_step(step, time.time_at(step), v);
  if (requests.empty()) return;
  sort_requests(requests);
  block.retire_requested(requests, step, time.time_at(step),
                         [&](std::size_t slot) { return energy_of(worker, block.batch, slot); });
}

void BlockStepper::advance_block(Block& block, std::size_t index, Worker& worker, std::uint64_t from,
                                 std::uint64_t to) {
  block.begin_chunk();
  for (StepObserver* watcher : step_watchers) watcher->save_block(view(block, index, worker));
  const double dt = time.dt;
  bool clean = true;
  try {
    // The common case: the whole chunk in one call, through the kernel when there is one, cut only at the steps a
    // watcher watches (none without watchers).
    if (!every_step())
      for (std::uint64_t step = from; step < to && !block.empty();) {
        const std::uint64_t next = std::min(to, next_watched(step));
        block.step_n(worker.stepping, dt, next - step);
        step = next;
        watch_step(block, index, worker, step);
      }
    else
      for (std::uint64_t step = from; step < to && !block.empty(); ++step) {
        block.step(worker.model, dt);
        watch_step(block, index, worker, step + 1);
      }
  } catch (const ModelError&) {
    clean = false;
  }
  if (clean && block.all_finite()) return;
  block.rollback_chunk();
  for (StepObserver* watcher : step_watchers) watcher->restore_block(view(block, index, worker));
  for (std::uint64_t step = from + 1; step <= to && !block.empty(); ++step) {
    checked_step(block, worker, step);
    if (!block.empty()) watch_step(block, index, worker, step);
  }
}

// One step of the block, from `step - 1` to `step`, retiring the states that fail or diverge. Without observers of
// every step the chunk it redoes went through the plugin's kernel (worker.stepping), and so does the step: the states
// that go on keep the numbers of a chunk that never stopped, wherever chunks end, on any instruction set. A step the
// plugin fails in goes through the evaluation path, the whole block and then state by state, so that the failed
// states' messages and the evaluation counts are those of a step-by-step run.
void BlockStepper::checked_step(Block& block, Worker& worker, std::uint64_t step) {
  const PhaseSpaceBatch before = block.batch;
  const std::optional<BlockTangents> tangents_before = block.tangents;  // vectors and the scheme's private state
  const Integrator integrator_before = block.integrator;  // the scheme's private state, for a redo state by state
  std::vector<std::string> errors(before.count());
  bool stepped = false;
  if (!every_step()) {
    try {
      block.step_n(worker.stepping, time.dt, 1);
      stepped = true;
    } catch (const ModelError&) {
      block.batch = before;
      block.tangents = tangents_before;
      block.integrator = integrator_before;
    }
  }
  if (!stepped) {
    errors = isolate_failures(block.batch, before, [&](PhaseSpaceBatch& x, std::size_t first) {
      if (block.tangents)
        block.tangents->step_part(worker.model, x, *tangents_before, first, time.dt);
      else if (x.count() == before.count())
        block.integrator.step(worker.model, x, time.dt);
      else
        block.integrator.step_part(worker.model, x, integrator_before, first, before.count(), time.dt);
    });
    if (block.tangents) block.tangents->after_step(worker.model, block.batch, time.dt);
  }
  std::vector<bool> retire(block.trajectories.size(), false);
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    Departure departure{0, {block.trajectories[slot], {}}};
    TrajectoryRecord& record = departure.stopped.record;
    if (!errors[slot].empty()) {
      record.status = TrajectoryStatus::failed;
      record.message = "the model failed at step " + std::to_string(step) + ": " + errors[slot];
    } else if (auto variable = first_non_finite(block.batch, slot); !variable.empty()) {
      record.status = TrajectoryStatus::diverged;
      record.stop_variable = variable;
    } else {
      continue;
    }
    retire[slot] = true;
    record.stop_step = step;
    record.stop_t = time.time_at(step);
    record_final_state(record, before, slot, step - 1, time.time_at(step - 1), energy_of(worker, before, slot));
    block.departures.push_back(std::move(departure));
  }
  block.compact(retire);
}

// H of state `slot` of x alone, or nothing when unknown.
std::optional<double> BlockStepper::energy_of(Worker& worker, const PhaseSpaceBatch& x, std::size_t slot) const {
  if (!energy_available) return std::nullopt;
  try {
    const double energy = worker.energy.evaluate_one(worker.model, single_state(x, slot));
    if (std::isfinite(energy)) return energy;
  } catch (const ModelError&) {
  }
  return std::nullopt;
}

// H of the block's states at `step`; the states the model fails on leave the block as "failed" departures.
void BlockStepper::evaluate_energies(Block& block, Worker& worker, std::uint64_t step) {
  const auto errors = compute_energies(block, worker, step);
  std::vector<bool> retire(block.trajectories.size(), false);
  for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
    if (errors[slot].empty()) continue;
    retire[slot] = true;
    Departure departure{1, {block.trajectories[slot], {}}};
    TrajectoryRecord& record = departure.stopped.record;
    record.status = TrajectoryStatus::failed;
    record.message = "the energy could not be evaluated at step " + std::to_string(step) + ": " + errors[slot];
    record.stop_step = step;
    record.stop_t = time.time_at(step);
    record_final_state(record, block.batch, slot, step, record.stop_t, std::nullopt);
    block.departures.push_back(std::move(departure));
  }
  block.compact(retire);
}

// Fills block.energies at `step` (NaN where the model fails); returns the model's message per slot.
std::vector<std::string> BlockStepper::compute_energies(Block& block, Worker& worker, std::uint64_t step) {
  block.energies.assign(block.trajectories.size(), std::nan(""));
  block.energy_step = step;
  PhaseSpaceBatch x = block.batch;
  auto errors = isolate_failures(x, block.batch, [&](PhaseSpaceBatch& part, std::size_t first) {
    worker.energy.evaluate(worker.model, part, std::span<double>(block.energies).subspan(first, part.count()));
  });
  for (std::size_t slot = 0; slot < errors.size(); ++slot)
    if (!errors[slot].empty()) block.energies[slot] = std::nan("");
  return errors;
}

}  // namespace nonsep::host
