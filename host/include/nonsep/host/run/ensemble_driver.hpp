#pragma once
// The ensemble driver: advances every trajectory of a run from step 0 (or a checkpoint) to the last step, and
// nothing else. No I/O: everything a run writes or tracks is an observer (observer.hpp).
//
// Blocks and threads. The trajectories are split into blocks of consecutive trajectories, sized from the ensemble
// (run_block_size_for: at most run_block_size, and at least run_min_blocks blocks when the ensemble allows, so that
// up to that many threads all have work), whatever the number of threads; each block is one nonsep::PhaseSpaceBatch
// with its own Integrator (one plugin call per stage for the whole block). Blocks run on `threads` worker threads,
// each thread with its own plugin instance (the ABI's contract). The plugin evaluates every state on its own, and the
// blocks do not depend on the thread count (the evaluation counts do depend on the blocks when trajectories stop
// early), so every number, and every observer's output, is the same for any number of threads.
//
// Chunks. From one event (an observer's next_event, the end; at most about `chunk_seconds` of stepping, sized from
// the speed of the chunk before) to the next, each block advances without per-step checks. When a block's chunk ends
// with a non-finite number or the plugin fails in it, the block goes back to its state at the chunk's start
// (integrator and every-step observers included) and redoes the chunk step by step with the checks below, through
// the kernel when the chunk went through it, so the numbers, evaluation counts and statuses are those of a run
// checked at every step. Where chunks end changes no number: outputs are the same byte for byte however long the
// chunks are.
//
// Per trajectory, at every step:
//   - a state with a non-finite q or p retires as "diverged" (stop step and the first non-finite variable, e.g.
//     "p[0]"); its final state is its last finite one;
//   - when the plugin fails on the block (nonsep::ModelError), the step is redone state by state from the previous
//     step's copy, and only the states the plugin fails on retire, as "failed" with the plugin's message.
// Removing a state from a block does not change the others' numbers. An every-step observer may also ask for a
// trajectory to stop at a step (BlockView::retire; e.g. at its last Poincare crossing).
//
// Energy: H (nonsep::EnergyEvaluator: the plugin's own energy_TTV/energy_VVT, else its Hessian-vector products, else
// its Hessians) is evaluated at step 0, at every event step an
// observer asks for (needs_energy), at the last step, and for the final state of a trajectory that stops early.
// A state whose H cannot be evaluated at an event retires as "failed".
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/run/trajectory.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

inline constexpr std::size_t run_block_size = 256;  // the most trajectories per block
inline constexpr std::size_t run_min_blocks = 8;    // the fewest blocks, when there are enough states
inline constexpr double run_chunk_seconds = 0.1;    // the wall time a chunk aims at (chunk_sizer.hpp)

// Trajectories per block for an ensemble of `trajectories`: the largest power of two from 2 up to run_block_size
// that still cuts it into at least run_min_blocks blocks (2 for fewer states: states stepped together stay in one
// plugin call, as plugins that tell batches from single states expect): 71 trajectories are 9 blocks of 8,
// 600 are 10 of 64, 2048 and more are blocks of 256. A power of two divides run_block_size, so the work units of a
// distributed run (multiples of run_block_size) cut no block.
std::size_t run_block_size_for(std::size_t trajectories);

// Consecutive trajectories evaluated with parameters of their own (a parameter sweep): from `first` up to the next
// set's first trajectory.
struct ParameterSet {
  std::size_t first = 0;
  nlohmann::json parameters;  // as given to Plugin::create
};

// What the driver integrates.
struct EnsembleSetup {
  IntegratorSpec integrator;
  TimeGrid time;
  std::size_t dimension = 0;
  std::span<const double> q, p;  // initial states, state-major (count * dimension each)
  unsigned threads = 0;  // worker threads; 0: all cores (omp_get_max_threads); 1 for a plugin that is not thread-safe
  const std::atomic<bool>* stop_requested = nullptr;  // checked between chunks
  // Tangent vectors per trajectory (/analysis/lyapunov, /megno; run/tangent_block.hpp), 0 for none; the plugin
  // must then have Hessians. The states are stepped bit for bit as without them.
  std::size_t tangent_vectors = 0;
  std::uint64_t renormalize_every = 1;
  // Trajectories per block: run_block_size_for of the whole ensemble, which a distributed run's work unit is part of
  // (its blocks are then those of the whole run); 0: run_block_size_for of these states.
  std::size_t block_size = 0;
  // The parameter sets, by increasing `first` (the first at 0); empty: every trajectory has `model`'s parameters.
  // A block never spans two sets (blocks are cut at every set's first trajectory as well as at the multiples of
  // block_size), and each thread creates its own instance of a set's parameters when it first steps one of its
  // blocks: one instance per set and thread (`model` is then not stepped).
  std::vector<ParameterSet> parameter_sets = {};
  // With tangent vectors: the chaos indicators computed from them (nonsep/core/analysis/indicator.hpp), in the order
  // of their columns; tangent_vectors is at least the most any of them needs.
  IndicatorList indicators = {};
  // The wall time each chunk aims at, from the speed of the chunk before (run/chunk_sizer.hpp); 0: one step each.
  // No number depends on it.
  double chunk_seconds = run_chunk_seconds;
};

// The driver's state between two steps, for checkpoints.
struct DriverState {
  std::uint64_t step = 0;                 // steps completed
  std::vector<std::size_t> active;        // the active trajectories, in trajectory order
  std::vector<double> q, p;               // their states, state-major
  std::vector<double> energies;           // their H at `step` (NaN when not evaluated there)
  std::vector<TrajectoryRecord> records;  // every trajectory, by index
  EvaluationCounts evaluations;
  // With tangent vectors (k per trajectory): the active trajectories' vectors (k * dimension numbers each, in
  // tangent_basic_step.hpp's layout), their Lyapunov sums, and per indicator of EnsembleSetup::indicators its state
  // of each (state_size numbers each); empty without.
  std::vector<double> tangent_q, tangent_p;
  std::vector<LyapunovRecord> lyapunov;
  struct IndicatorState {
    std::string name;            // Indicator::name()
    std::vector<double> values;  // state_size numbers per active trajectory, in the order of `active`
  };
  std::vector<IndicatorState> indicators;
  // The scheme's private state of the active trajectories (its columns in the order of `active`) and its numbers
  // about the run (nonsep::SchemeState): stored and handed back, never read; empty for most schemes.
  SchemeState scheme;
};

// How the stepping ended.
enum class DriverEnd {
  completed,    // the last step was reached (or every trajectory stopped early)
  interrupted,  // stop_requested was set
  failed,       // an error that is not one trajectory's (thrown by an observer, the machine, ...): error()
};

class EnsembleDriver {
 public:
  // `model` is an instance of `plugin` created with the job's parameters; other threads get their own instances.
  EnsembleDriver(const Plugin& plugin, const PluginModel& model, EnsembleSetup setup);
  ~EnsembleDriver();
  EnsembleDriver(const EnsembleDriver&) = delete;
  EnsembleDriver& operator=(const EnsembleDriver&) = delete;

  // Observers, called in the order added. Not owned; must outlive run().
  void add_observer(Observer& observer);
  // Continue from a checkpoint instead of step 0 (before run()).
  void restore(DriverState state);
  // The state after the last completed step (between chunks; observers call it from after_chunk or
  // before_finish).
  DriverState state() const;

  // Steps to the end, then retires every active state (completed, or interrupted when the run stopped early) and
  // calls on_end. Never throws for one trajectory's problems; an error of the run as a whole ends it as failed.
  DriverEnd run();

  const std::vector<TrajectoryRecord>& records() const;
  EvaluationCounts evaluations() const;
  // What the scheme reports about this process's steps (Integrator::report), the largest of every block's numbers;
  // empty for most schemes.
  std::vector<SchemeFigure> scheme_report() const;
  // Calls of the plugin's stepping kernel in this process (0: every step went through the evaluation path). The
  // kernel takes the chunks no every-step observer watches, without tangent vectors; replays after a failure and
  // every other step go through the evaluations.
  std::uint64_t kernel_calls() const;
  std::uint64_t steps_completed() const;
  std::size_t active_count() const;
  const std::string& error() const;  // why the run failed (DriverEnd::failed)
  const TimeGrid& time() const;
  bool energy_available() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nonsep::host
