#include "nonsep/host/run/ensemble_driver.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <tuple>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/error.hpp"
#include "run/block.hpp"
#include "run/block_stepper.hpp"
#include "run/chunk_sizer.hpp"
#include "run/worker_pool.hpp"

namespace nonsep::host {

struct EnsembleDriver::Impl {
  const Plugin& plugin;
  EnsembleSetup setup;
  bool energy_available;
  std::vector<TrajectoryRecord> records;
  std::vector<Block> blocks;
  std::size_t block_size = run_block_size;  // trajectories per block (the last may have fewer)
  std::vector<std::size_t> block_first;     // each block's first trajectory
  std::vector<std::size_t> block_set;       // each block's parameter set
  std::vector<nlohmann::json> set_parameters;
  // workers[thread][set]: created by that thread on first use (worker()); without parameter sets, thread 0's is
  // `model` itself.
  std::vector<std::vector<std::unique_ptr<Worker>>> workers;
  std::mutex creating;  // Plugin::create from several threads
  std::vector<Observer*> observers;
  std::vector<ChunkObserver*> chunk_observers;
  std::vector<StepObserver*> step_watchers;
  std::unique_ptr<WorkerPool> pool;  // after `workers`: destroyed (its threads joined) before them
  BlockStepper stepper{setup.dimension, setup.time, step_watchers, energy_available};
  ChunkSizer chunks{setup.chunk_seconds};
  std::uint64_t completed = 0;
  bool resumed = false;
  EvaluationCounts evaluations_before;
  std::string error;
  std::size_t indicator_columns = 0;  // the columns of setup.indicators, together

  Impl(const Plugin& p, const PluginModel& model, EnsembleSetup s)
      : plugin(p), setup(std::move(s)), energy_available(p.has_energy()), records(setup.q.size() / setup.dimension) {
    const std::size_t n = setup.dimension, count = records.size();
    // A plugin that is not thread-safe ("thread_safe": false, plugin_abi.h) gets one instance on one thread.
    const unsigned requested = !plugin.thread_safe() ? 1u
                               : setup.threads > 0   ? setup.threads
                                                     : static_cast<unsigned>(omp_get_max_threads());
    block_size = setup.block_size > 0 ? setup.block_size : run_block_size_for(count);
    for (const auto& indicator : setup.indicators) indicator_columns += indicator->columns().size();
    const bool own_sets = !setup.parameter_sets.empty();
    if (!own_sets) setup.parameter_sets.push_back({0, model.parameters()});
    for (const ParameterSet& set : setup.parameter_sets) set_parameters.push_back(set.parameters);
    std::size_t set = 0;
    for (std::size_t first = 0; first < count;) {
      while (set + 1 < setup.parameter_sets.size() && setup.parameter_sets[set + 1].first <= first) ++set;
      std::size_t end = std::min(count, (first / block_size + 1) * block_size);
      if (set + 1 < setup.parameter_sets.size()) end = std::min(end, setup.parameter_sets[set + 1].first);
      const std::size_t size = end - first;
      block_first.push_back(first);
      block_set.push_back(set);
      std::vector<std::size_t> members(size);
      std::iota(members.begin(), members.end(), first);
      blocks.emplace_back(setup.integrator, n, members, setup.q.subspan(first * n, size * n),
                          setup.p.subspan(first * n, size * n));
      if (setup.tangent_vectors > 0) {
        blocks.back().tangents.emplace(setup, size);
        blocks.back().tangents->start();
      }
      first = end;
    }
    const std::size_t threads = std::max<std::size_t>(1, std::min<std::size_t>(requested, blocks.size()));
    workers.resize(threads);
    for (auto& sets : workers) sets.resize(set_parameters.size());
    if (!own_sets) workers[0][0] = std::make_unique<Worker>(Worker{model, EnergyEvaluator(setup.integrator.form)});
    pool = std::make_unique<WorkerPool>(workers.size());
  }

  // Thread `thread`'s instance of parameter set `set`, created on its first use.
  Worker& worker(std::size_t thread, std::size_t set) {
    std::unique_ptr<Worker>& worker = workers[thread][set];
    if (!worker) {
      PluginModel model;
      {
        const std::lock_guard lock(creating);
        model = plugin.create(set_parameters[set]);
      }
      worker = std::make_unique<Worker>(Worker{std::move(model), EnergyEvaluator(setup.integrator.form)});
    }
    return *worker;
  }

  // Runs `action(block, worker)` on every block with a state left, blocks spread over the workers' threads.
  // Exceptions are kept per block; the first in block order is rethrown after all blocks are done.
  template <class Action>
  void for_each_block(Action&& action) {
    // Threads of a WorkerPool, not an OpenMP region: they sleep between chunks instead of spinning (worker_pool.hpp).
    pool->run(blocks.size(), [&](std::size_t index, std::size_t thread) {
      Block& block = blocks[index];
      if (block.empty()) return;
      try {
        action(block, worker(thread, block_set[index]));
      } catch (...) {
        block.error = std::current_exception();
      }
    });
    for (Block& block : blocks)
      if (block.error) {
        const auto thrown = block.error;
        for (Block& b : blocks) b.error = nullptr;
        std::rethrow_exception(thrown);
      }
  }

  std::size_t active_count() const {
    std::size_t count = 0;
    for (const Block& block : blocks) count += block.trajectories.size();
    return count;
  }

  bool energy_step(std::uint64_t step) const {
    if (!energy_available) return false;
    if (step == setup.time.steps) return true;
    return std::any_of(observers.begin(), observers.end(), [&](Observer* o) { return o->needs_energy(step); });
  }

  std::uint64_t next_event(std::uint64_t from) const {
    std::uint64_t to = setup.time.steps;
    for (Observer* observer : observers) to = std::min(to, std::max(from + 1, observer->next_event(from)));
    return std::min(to, from + chunks.longest(active_count()));
  }

  // Tells the observers that `trajectory` stopped; its record is final.
  void announce(std::size_t trajectory) {
    for (Observer* observer : observers) observer->on_retire(trajectory, records[trajectory]);
  }

  // Moves the blocks' departures into the records (each keeps its H0), in the order a step-by-step run finds them.
  void apply_departures() {
    std::vector<Departure> departures;
    for (Block& block : blocks) {
      std::move(block.departures.begin(), block.departures.end(), std::back_inserter(departures));
      block.departures.clear();
    }
    std::sort(departures.begin(), departures.end(), [](const Departure& a, const Departure& b) {
      return std::tie(a.stopped.record.stop_step, a.phase, a.stopped.trajectory) <
             std::tie(b.stopped.record.stop_step, b.phase, b.stopped.trajectory);
    });
    for (Departure& departure : departures) {
      TrajectoryRecord& record = records[departure.stopped.trajectory];
      departure.stopped.record.energy_initial = record.energy_initial;
      record = std::move(departure.stopped.record);
      announce(departure.stopped.trajectory);
    }
  }

  // The event at `step`: the active states to every observer; retirements they ask for are applied after all.
  void notify_event(std::uint64_t step, bool energy_evaluated) {
    std::vector<StateView> states;
    states.reserve(active_count());
    // The indicators' values of every active state, one after the other (their columns per state).
    std::vector<double> values;
    const std::size_t columns = indicator_columns;
    if (columns > 0) values.reserve(active_count() * columns);
    for (const Block& block : blocks)
      for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
        if (block.tangents) block.tangents->values(slot, values);
        states.push_back({block.trajectories[slot], block.batch.q(slot), block.batch.p(slot),
                          block.energy_step == step ? block.energy(slot) : std::nullopt,
                          &records[block.trajectories[slot]]});
      }
    if (!values.empty())
      for (std::size_t s = 0; s < states.size(); ++s)
        states[s].indicators = std::span<const double>(values).subspan(s * columns, columns);
    std::vector<StoppedTrajectory> requests;
    const Event event{step, setup.time.time_at(step), states, energy_evaluated, &requests};
    for (Observer* observer : observers) observer->on_event(event);
    if (requests.empty()) return;
    sort_requests(requests);
    for (Block& block : blocks)
      block.retire_requested(requests, step, event.t, [&](std::size_t slot) {
        return block.energy_step == step ? block.energy(slot) : std::nullopt;
      });
    apply_departures();
  }

  // Every block from step `from` to `to`, then H at `to` when asked for, then the event.
  void advance(std::uint64_t from, std::uint64_t to) {
    try {
      for_each_block([&](Block& block, Worker& worker) {
        stepper.advance_block(block, static_cast<std::size_t>(&block - blocks.data()), worker, from, to);
      });
    } catch (...) {
      for (Block& block : blocks) block.abandon_chunk();  // the run ends at `from`
      throw;
    }
    apply_departures();
    completed = to;
    const bool energy = energy_step(to);
    if (energy) {
      for_each_block([&](Block& block, Worker& worker) { stepper.evaluate_energies(block, worker, to); });
      apply_departures();
    }
    notify_event(to, energy);
  }

  // H0 of the states whose H is known at step 0 (each trajectory belongs to one block: no two threads touch the
  // same record).
  void start() {
    if (energy_available)
      for_each_block([&](Block& block, Worker& worker) {
        stepper.evaluate_energies(block, worker, 0);
        for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
          records[block.trajectories[slot]].energy_initial = block.energy(slot);
      });
    apply_departures();
    // The indicators that measure the first tangent vector across the flow take it at time 0 with each block's model
    // (a parameter set's own).
    if (setup.tangent_vectors > 0)
      for_each_block(
          [&](Block& block, Worker& worker) { block.tangents->start_across_flow(worker.model, block.batch); });
    notify_event(0, energy_available);
  }

  // The states still active when the stepping ends: completed or interrupted. Their H is evaluated at `completed`
  // unless it already was; a state whose H then fails keeps a null energy.
  void finish_active(TrajectoryStatus status) {
    if (energy_available) {
      try {
        for_each_block([&](Block& block, Worker& worker) {
          if (block.energy_step != completed) BlockStepper::compute_energies(block, worker, completed);
        });
      } catch (const std::exception& thrown) {
        if (error.empty()) error = thrown.what();
      }
    }
    for (Block& block : blocks) {
      for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
        TrajectoryRecord& record = records[block.trajectories[slot]];
        record.status = status;
        if (!error.empty()) record.message = error;
        block.final_estimates(slot, record);
        try {
          record_final_state(record, block.batch, slot, completed, setup.time.time_at(completed),
                             block.energy_step == completed ? block.energy(slot) : std::nullopt);
          announce(block.trajectories[slot]);
        } catch (const std::exception& thrown) {
          if (error.empty()) error = thrown.what();
        }
      }
      block.clear();
    }
  }
};

std::size_t run_block_size_for(std::size_t trajectories) {
  std::size_t size = run_block_size;
  while (size > 2 && (trajectories + size - 1) / size < run_min_blocks) size /= 2;
  return size;
}

EnsembleDriver::EnsembleDriver(const Plugin& plugin, const PluginModel& model, EnsembleSetup setup)
    : impl_(std::make_unique<Impl>(plugin, model, std::move(setup))) {}
EnsembleDriver::~EnsembleDriver() = default;

void EnsembleDriver::add_observer(Observer& observer) {
  impl_->observers.push_back(&observer);
  if (auto* chunks = dynamic_cast<ChunkObserver*>(&observer)) impl_->chunk_observers.push_back(chunks);
  if (auto* steps = dynamic_cast<StepObserver*>(&observer)) impl_->step_watchers.push_back(steps);
}

DriverEnd EnsembleDriver::run() {
  Impl& d = *impl_;
  for (ChunkObserver* observer : d.chunk_observers) observer->prepare_blocks(d.blocks.size());
  bool interrupted = false;
  try {
    if (!d.resumed) d.start();
    while (d.completed < d.setup.time.steps && d.active_count() > 0) {
      if (d.setup.stop_requested && d.setup.stop_requested->load()) {
        interrupted = true;
        break;
      }
      const std::uint64_t from = d.completed;
      const std::size_t active = d.active_count();
      const auto start = std::chrono::steady_clock::now();
      d.advance(from, d.next_event(from));
      d.chunks.measured(d.completed - from, active,
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      for (ChunkObserver* observer : d.chunk_observers) observer->after_chunk(d.completed);
    }
    for (ChunkObserver* observer : d.chunk_observers) observer->before_finish(d.completed, interrupted);
  } catch (const std::exception& thrown) {
    d.error = thrown.what();
  }
  const bool finished = d.completed == d.setup.time.steps && !interrupted;
  d.finish_active(!d.error.empty() ? TrajectoryStatus::failed
                  : finished       ? TrajectoryStatus::completed
                                   : TrajectoryStatus::interrupted);
  for (Observer* observer : d.observers) {
    try {
      observer->on_end();
    } catch (const std::exception& thrown) {
      if (d.error.empty()) d.error = thrown.what();
    }
  }
  if (!d.error.empty()) return DriverEnd::failed;
  return interrupted ? DriverEnd::interrupted : DriverEnd::completed;
}

void EnsembleDriver::restore(DriverState state) {
  Impl& d = *impl_;
  const std::size_t n = d.setup.dimension;
  std::vector<std::vector<std::size_t>> members(d.blocks.size());
  for (std::size_t k = 0; k < state.active.size(); ++k) {
    const auto after = std::upper_bound(d.block_first.begin(), d.block_first.end(), state.active[k]);
    members[static_cast<std::size_t>(after - d.block_first.begin()) - 1].push_back(k);
  }
  for (std::size_t b = 0; b < d.blocks.size(); ++b) {
    std::vector<std::size_t> trajectories;
    std::vector<double> q, p, energies;
    for (std::size_t k : members[b]) {
      trajectories.push_back(state.active[k]);
      q.insert(q.end(), state.q.begin() + static_cast<std::ptrdiff_t>(k * n),
               state.q.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      p.insert(p.end(), state.p.begin() + static_cast<std::ptrdiff_t>(k * n),
               state.p.begin() + static_cast<std::ptrdiff_t>((k + 1) * n));
      energies.push_back(state.energies[k]);
    }
    d.blocks[b] = Block(d.setup.integrator, n, trajectories, q, p);
    if (d.setup.tangent_vectors > 0)
      d.blocks[b].tangents.emplace(d.setup, trajectories.size()).restore(members[b], state);
    d.blocks[b].energies = std::move(energies);
    d.blocks[b].energy_step = state.step;
    if (!members[b].empty()) d.blocks[b].restore_scheme_state(state.scheme.select(members[b]));
  }
  d.records = std::move(state.records);
  d.completed = state.step;
  d.evaluations_before = state.evaluations;
  d.resumed = true;
}

DriverState EnsembleDriver::state() const {
  const Impl& d = *impl_;
  DriverState state;
  state.step = d.completed;
  state.scheme = scheme_state_layout(d.setup.integrator, d.setup.tangent_vectors, d.setup.dimension);
  if (d.setup.tangent_vectors > 0)
    for (const auto& indicator : d.setup.indicators) state.indicators.push_back({indicator->name(), {}});
  for (const Block& block : d.blocks) {
    state.active.insert(state.active.end(), block.trajectories.begin(), block.trajectories.end());
    state.q.insert(state.q.end(), block.batch.q().begin(), block.batch.q().end());
    state.p.insert(state.p.end(), block.batch.p().begin(), block.batch.p().end());
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
      state.energies.push_back(block.energy_step == d.completed ? block.energies[slot] : std::nan(""));
    if (block.tangents) block.tangents->save(state);
    state.scheme.append(block.save_scheme_state());
  }
  state.records = d.records;
  state.evaluations = evaluations();
  return state;
}

const std::vector<TrajectoryRecord>& EnsembleDriver::records() const { return impl_->records; }
EvaluationCounts EnsembleDriver::evaluations() const {
  EvaluationCounts counts = impl_->evaluations_before;
  for (const Block& block : impl_->blocks) counts += block.evaluations();
  return counts;
}
std::vector<SchemeFigure> EnsembleDriver::scheme_report() const {
  std::vector<SchemeFigure> report = Integrator(impl_->setup.integrator).report();
  for (const Block& block : impl_->blocks) {
    const std::vector<SchemeFigure> part = block.scheme_report();
    for (std::size_t i = 0; i < report.size() && i < part.size(); ++i)
      report[i].value = std::max(report[i].value, part[i].value);
  }
  return report;
}
std::uint64_t EnsembleDriver::kernel_calls() const {
  std::uint64_t calls = 0;
  for (const auto& sets : impl_->workers)
    for (const auto& worker : sets)
      if (worker) calls += worker->stepping.kernel_calls();
  return calls;
}
std::uint64_t EnsembleDriver::steps_completed() const { return impl_->completed; }
std::size_t EnsembleDriver::active_count() const { return impl_->active_count(); }
const std::string& EnsembleDriver::error() const { return impl_->error; }
const TimeGrid& EnsembleDriver::time() const { return impl_->setup.time; }
bool EnsembleDriver::energy_available() const { return impl_->energy_available; }

}  // namespace nonsep::host
