#pragma once
// Observers watch an ensemble that the EnsembleDriver (ensemble_driver.hpp) advances; everything that happens
// during a run besides stepping is one: the trajectory.csv writer, the energy-error tracker, the closest-return
// analysis, the checkpoint saver, the progress bar. Adding one does not touch the driver (Odeint's integrate_*
// with an observer).
//
// What the driver calls, and when (all on the driver's thread unless said otherwise):
//   next_event(step)       the first step after `step` at which the observer must see the ensemble; the driver
//                          ends its chunk of unchecked stepping there. Default: none.
//   needs_energy(step)     whether H must be evaluated at event `step` (the driver then evaluates it for every
//                          active state before on_event). H is always evaluated at step 0 and at the last step.
//   on_event(event)        at step 0 (a fresh run) and at every event step of any observer, after the states that
//                          stopped in the chunk were retired: the active states in trajectory order, with H where
//                          it was evaluated. May ask for trajectories to be retired (event.retire).
//   on_retire(...)         a trajectory stopped: early (diverged, failed, inaccurate) in the order a step-by-step
//                          run finds them (step, then energy failures, then trajectory index), or at the end of the
//                          run (completed, interrupted), in trajectory order. Its record is final.
//   after_chunk(step)      after every chunk (about EnsembleSetup::chunk_seconds of stepping at most: 0.1 s).
//   before_finish(step, interrupted)  the stepping is over, before the active states are retired.
//   on_end()               after the last retirement: flush, close.
// The interface is small, as Odeint's observer is one callable: Observer has the events every observer may want;
// what few observers need are facets, separate small interfaces an observer also derives from: ChunkObserver
// (prepare_blocks, after_chunk, before_finish) and StepObserver (every step, or every k-th), which the driver finds
// by dynamic_cast when the observer is added, and CheckpointedObserver (save, restore) and TrajectoryColumns
// (trajectories.csv), which the run's plan lists by the observers' types (launch/).
// Observers that watch steps (StepObserver) are called inside chunks, on the worker thread of each block, with that
// block's states only (on_step); they must touch nothing but their state for those
// trajectories. Before a chunk the driver calls save_block; when a chunk is redone step by step (a state stopped
// being finite, or the plugin failed, somewhere in it) restore_block puts the block's trajectories back. The view
// carries the worker thread's plugin instance (BlockView::model), for observers that must evaluate or step a state
// themselves (a Poincare section re-steps from the state before the step), and in on_step a list where the
// observer may ask for trajectories to stop at this step (BlockView::retire: the driver removes them from the block
// after every watcher saw the step; their final state is the state at this step).
//
// Checkpoints: save() returns the observer's state as JSON (numbers as shortest round-trip strings), restore()
// takes it back after a resume and reads it with the one reader, SavedState (saved_state.hpp); a resumed run must
// end bit for bit as an uninterrupted one. The observer knows nothing of the checkpoint file.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nonsep/host/run/trajectory.hpp"

namespace nonsep::host {

class PluginModel;

inline constexpr std::uint64_t no_event = std::numeric_limits<std::uint64_t>::max();

// One active state at an event.
struct StateView {
  std::size_t trajectory = 0;
  std::span<const double> q, p;
  std::optional<double> energy;              // H at this step, when it was evaluated and finite
  const TrajectoryRecord* record = nullptr;  // energy_initial etc.
  // When the run computes chaos indicators (EnsembleSetup::indicators): their columns' running values, in order.
  std::span<const double> indicators = {};
};

struct Event {
  std::uint64_t step = 0;
  double t = 0.0;
  std::span<const StateView> states;  // trajectory order
  bool energy_evaluated = false;      // H was evaluated at this step (StateView::energy may still be empty)
  // Stops the observer asks for: each trajectory stops here with its record's status and message (trajectory.hpp).
  std::vector<StoppedTrajectory>* retire = nullptr;
};

// The states of one block inside a chunk (on_step): trajectories[s] is the index of slot s, its q at
// q[s*n .. s*n+n), p likewise.
struct BlockView {
  std::size_t block = 0;
  std::size_t dimension = 0;
  std::span<const std::size_t> trajectories;
  std::span<const double> q, p;
  const PluginModel* model = nullptr;                // the worker thread's plugin instance; use it on this thread only
  std::vector<StoppedTrajectory>* retire = nullptr;  // on_step only: stop these trajectories at this step
};

// The observer every observer is: the events of the run, seen on the driver's thread.
class Observer {
 public:
  virtual ~Observer() = default;

  virtual std::uint64_t next_event(std::uint64_t /*step*/) const { return no_event; }
  virtual bool needs_energy(std::uint64_t /*step*/) const { return false; }
  virtual void on_event(const Event& /*event*/) {}
  virtual void on_retire(std::size_t /*trajectory*/, const TrajectoryRecord& /*record*/) {}
  virtual void on_end() {}
};

// Facet: the course of the run between chunks (prepare_blocks once before stepping, with the number of blocks;
// after_chunk; before_finish).
class ChunkObserver {
 public:
  virtual ~ChunkObserver() = default;
  virtual void prepare_blocks(std::size_t /*blocks*/) {}
  virtual void after_chunk(std::uint64_t /*step*/) {}
  virtual void before_finish(std::uint64_t /*step*/, bool /*interrupted*/) {}
};

// Facet: every step, inside chunks, on the worker threads (see above). stride() 0 (the default): every step, and the
// block steps one step at a time on the evaluation path (for observers that step states themselves); k >= 1: the
// steps that are multiples of k, the block stepping between them through the plugin's kernel, as a run without
// watchers does (the same numbers: a kernel call cut anywhere ends where the whole call ends).
class StepObserver {
 public:
  virtual ~StepObserver() = default;
  virtual std::uint64_t stride() const { return 0; }
  virtual void on_step(std::uint64_t step, double t, const BlockView& block) = 0;
  virtual void save_block(const BlockView& block) = 0;
  virtual void restore_block(const BlockView& block) = 0;
};

// Facet: state for checkpoints. `name()` keys it in checkpoint.json (empty: nothing to save); save() returns it as
// JSON, restore() takes it back and reads it with a SavedState (saved_state.hpp), which refuses a damaged one.
class CheckpointedObserver {
 public:
  virtual ~CheckpointedObserver() = default;
  virtual std::string name() const = 0;
  virtual nlohmann::json save() = 0;
  virtual void restore(const nlohmann::json& state) = 0;
};

// Facet: per-trajectory columns of trajectories.csv: columns() names them, cells() writes a trajectory's.
class TrajectoryColumns {
 public:
  virtual ~TrajectoryColumns() = default;
  virtual void columns(std::vector<std::string>& names) const = 0;
  virtual void cells(std::size_t trajectory, std::string& row) const = 0;
};

}  // namespace nonsep::host
