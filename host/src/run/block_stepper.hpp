#pragma once
// Internal to the ensemble driver (ensemble_driver.cpp): what a worker thread does to one block of trajectories
// inside a chunk. It steps the block without checks and, when the chunk ends with a non-finite number or the
// plugin failed in it, puts the block back and redoes the chunk step by step, retiring the states that fail or
// diverge (Departure, block.hpp: their records, trajectory.hpp); it shows the observers that watch steps the steps
// they watch, and evaluates H. The driver decides which blocks run where and when; this class knows one block at a
// time.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"
#include "run/block.hpp"

namespace nonsep::host {

// What one thread owns: a plugin instance (as the evaluation path's model, and as the model whose chin_steps runs
// the plugin's kernel when it has one) and an energy evaluator's workspace.
struct alignas(64) Worker {
  PluginModel model;
  EnergyEvaluator energy;
  PluginModel stepping = model.with_kernel();
};

class BlockStepper {
 public:
  // `time` and `step_watchers` are the driver's and outlive the stepper.
  BlockStepper(std::size_t dimension, const TimeGrid& time, const std::vector<StepObserver*>& step_watchers,
               bool energy_available)
      : dimension(dimension), time(time), step_watchers(step_watchers), energy_available(energy_available) {}

  // Steps `block`, the driver's block number `index`, from step `from` to `to` (see above); the states that stop
  // are in block.departures.
  void advance_block(Block& block, std::size_t index, Worker& worker, std::uint64_t from, std::uint64_t to);
  // H of the block's states at `step` (block.energies); the states the model fails on leave the block as "failed"
  // departures.
  void evaluate_energies(Block& block, Worker& worker, std::uint64_t step);
  // Fills block.energies at `step` (NaN where the model fails); returns the model's message per slot.
  static std::vector<std::string> compute_energies(Block& block, Worker& worker, std::uint64_t step);

 private:
  BlockView view(const Block& block, std::size_t index, const Worker& worker) const;
  // Whether a watcher watches every step (then the block steps one step at a time on the evaluation path), and the
  // first step after `step` that a watcher watches.
  bool every_step() const;
  std::uint64_t next_watched(std::uint64_t step) const;
  void watch_step(Block& block, std::size_t index, Worker& worker, std::uint64_t step);
  void checked_step(Block& block, Worker& worker, std::uint64_t step);
  std::optional<double> energy_of(Worker& worker, const PhaseSpaceBatch& x, std::size_t slot) const;

  std::size_t dimension;
  const TimeGrid& time;
  const std::vector<StepObserver*>& step_watchers;
  bool energy_available;
};

}  // namespace nonsep::host
