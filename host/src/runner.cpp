#include "nonsep/host/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <exception>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <omp.h>

#include "nonsep/core/energy.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/host/checkpoint.hpp"
#include "nonsep/host/output_files.hpp"
#include "nonsep/host/progress_bar.hpp"
#include "nonsep/host/summary_json.hpp"

namespace nonsep::host {

using json = nlohmann::ordered_json;

namespace {

using Clock = std::chrono::steady_clock;

// The first non-finite variable of state `slot` ("q[0]", "p[2]"), or "".
std::string first_non_finite(const PhaseSpaceBatch& x, std::size_t slot) {
  const auto q = x.q(slot), p = x.p(slot);
  for (std::size_t i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i])) return "q[" + std::to_string(i) + "]";
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!std::isfinite(p[i])) return "p[" + std::to_string(i) + "]";
  return "";
}

PhaseSpaceBatch single_state(const PhaseSpaceBatch& x, std::size_t slot) {
  return PhaseSpaceBatch::single(x.q(slot), x.p(slot));
}

void copy_state(const PhaseSpaceBatch& from, std::size_t from_slot, PhaseSpaceBatch& to, std::size_t to_slot) {
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

// NONSEP_FUSED=0 in the environment switches the fused path off (RunOptions::fused).
bool fused_switched_off_by_environment() {
  const char* value = std::getenv("NONSEP_FUSED");
  return value != nullptr && std::string(value) == "0";
}

bool all_finite(const PhaseSpaceBatch& x) {
  bool finite = true;
  for (double v : x.q()) finite &= std::isfinite(v);
  for (double v : x.p()) finite &= std::isfinite(v);
  return finite;
}

// A trajectory that stops before the end of the run, as found by its block's worker. The main thread applies
// departures to the records in (step, phase, trajectory) order, which is the order a step-by-step run finds them.
struct Departure {
  std::size_t trajectory = 0;
  std::uint64_t step = 0;        // the step at which it was found
  int phase = 0;                 // 0: while stepping, 1: while evaluating H at `step`
  std::uint64_t final_step = 0;  // the step of its final state
  std::string status;            // "diverged" or "failed"
  std::string variable;          // diverged: the first non-finite variable
  std::string error;             // failed: why
  std::vector<double> q, p;      // the final state
  std::optional<double> energy;  // H of the final state, when known
};

// Consecutive trajectories stepped together; the unit of work of a thread (see runner.hpp).
struct alignas(64) Block {  // a cache line of its own: threads count evaluations in neighbouring blocks
  PhaseSpaceBatch batch;
  std::vector<std::size_t> trajectories;   // slot in batch -> trajectory index
  Integrator integrator;
  std::vector<double> energies;            // per slot at energy_step (NaN when unknown)
  std::optional<std::uint64_t> energy_step;
  std::vector<Departure> departures;       // found in the current chunk
  PhaseSpaceBatch chunk_start;             // the block at the start of the current chunk
  std::optional<Integrator> chunk_start_integrator;
  std::vector<TrajectoryRecord> chunk_start_closest;  // with closest-return analysis: the records' fields then
  std::exception_ptr error;                // anything but a ModelError, thrown in the current chunk

  explicit Block(const IntegratorSpec& spec) : integrator(spec) {}
};

// What one thread owns: a plugin instance and an energy evaluator's workspace.
struct alignas(64) Worker {
  PluginModel model;
  EnergyEvaluator energy;
};

class Run {
 public:
  Run(const LoadedJob& loaded, const RunOptions& options)
      : job_(loaded.job),
        plugin_(loaded.plugin),
        model_(loaded.model),
        options_(options),
        prototype_(job_.integrator),
        fused_(options.fused && !fused_switched_off_by_environment()),
        energy_available_(loaded.plugin.has_hessians()),
        records_(job_.initial.count) {
    fingerprint_ = job_fingerprint(loaded);
    std::error_code error;
    std::filesystem::create_directories(options.output_directory, error);
    if (error)
      throw OutputError("cannot create the output folder " + options.output_directory.string() + ": " +
                        error.message());
    const auto trajectory_path = options.output_directory / "trajectory.csv";
    if (options.resume) {
      create_workers();
      resume(load_checkpoint(checkpoint_path(), loaded), trajectory_path);
      return;
    }
    if (job_.every > 0)
      writer_.emplace(trajectory_path, job_.initial.dimension);
    else
      std::filesystem::remove(trajectory_path, error);  // a file from an earlier run would mislead
    const std::size_t n = job_.initial.dimension;
    for (std::size_t first = 0; first < job_.initial.count; first += run_block_size) {
      const std::size_t count = std::min(run_block_size, job_.initial.count - first);
      Block& block = blocks_.emplace_back(job_.integrator);
      block.batch = PhaseSpaceBatch(n, count);
      const auto offset = static_cast<std::ptrdiff_t>(first * n), size = static_cast<std::ptrdiff_t>(count * n);
      std::copy(job_.initial.q.begin() + offset, job_.initial.q.begin() + offset + size, block.batch.q().begin());
      std::copy(job_.initial.p.begin() + offset, job_.initial.p.begin() + offset + size, block.batch.p().begin());
      block.trajectories.resize(count);
      std::iota(block.trajectories.begin(), block.trajectories.end(), first);
      block.energies.assign(count, std::nan(""));
    }
    create_workers();
  }

  void create_workers() {
    const unsigned requested = options_.threads > 0 ? options_.threads : static_cast<unsigned>(omp_get_max_threads());
    const std::size_t blocks = (job_.initial.count + run_block_size - 1) / run_block_size;
    const std::size_t threads = std::max<std::size_t>(1, std::min<std::size_t>(requested, blocks));
    workers_.push_back(Worker{model_, EnergyEvaluator(job_.integrator.form)});
    for (std::size_t t = 1; t < threads; ++t)
      workers_.push_back(Worker{plugin_.create(model_.parameters()), EnergyEvaluator(job_.integrator.form)});
  }

  RunOutcome execute() {
    const auto start = Clock::now();
    ProgressBar progress(options_.show_progress, job_.time.steps);
    auto next_flush = start + std::chrono::seconds(1);
    const auto checkpoint_interval = std::chrono::duration<double>(job_.checkpoint.every_seconds);
    auto next_checkpoint = start + std::chrono::duration_cast<Clock::duration>(checkpoint_interval);
    try {
      if (!resumed_) {
        for_each_block([&](Block& block, Worker& worker) { evaluate_energies(block, worker, 0); });
        apply_departures();
        write_samples(0);
      }
      while (completed_ < job_.time.steps && active_count() > 0) {
        if (options_.stop_requested && options_.stop_requested->load()) {
          interrupted_ = true;
          break;
        }
        advance(completed_, next_event(completed_));
        const auto now = Clock::now();
        if ((job_.checkpoint.every_steps > 0 && completed_ % job_.checkpoint.every_steps == 0) ||
            (job_.checkpoint.every_seconds > 0.0 && now >= next_checkpoint)) {
          save_state();
          next_checkpoint = now + std::chrono::duration_cast<Clock::duration>(checkpoint_interval);
          next_flush = now + std::chrono::seconds(1);
        } else if (writer_ && now >= next_flush) {
          writer_->flush();
          next_flush = now + std::chrono::seconds(1);
        }
        progress.update(completed_, job_.time.time_at(completed_), active_count());
      }
      // An interrupted run keeps where it stopped, before its last rows (finish_active) are written.
      if (interrupted_) save_state();
    } catch (const std::exception& error) {
      run_error_ = error.what();
    }
    progress.finish();
    if (!interrupted_ && run_error_.empty()) {
      std::error_code ignored;
      std::filesystem::remove(checkpoint_path(), ignored);
    }
    finish_active();
    if (writer_) {
      try {
        writer_->flush();
      } catch (const OutputError& error) {
        if (run_error_.empty()) run_error_ = error.what();
      }
    }
    RunOutcome outcome;
    outcome.summary = summary(std::chrono::duration<double>(Clock::now() - start).count());
    outcome.exit_status = exit_status();
    try {
      write_summary_json(options_.output_directory / "summary.json", outcome.summary,
                         {records_, job_.initial.q, job_.initial.p, job_.initial.dimension,
                          job_.analysis.closest_return_after.has_value()},
                         static_cast<unsigned>(workers_.size()));
    } catch (const OutputError& error) {
      outcome.summary["error"] = (run_error_.empty() ? "" : run_error_ + "; ") + error.what();
      if (outcome.exit_status == ExitStatus::success) outcome.exit_status = ExitStatus::run_failed;
    }
    outcome.summary.erase("trajectories");
    outcome.trajectories = std::move(records_);
    return outcome;
  }

 private:
  std::filesystem::path checkpoint_path() const { return options_.output_directory / checkpoint_file_name; }

  // Flushes trajectory.csv and saves checkpoint.json for the state after step completed_: the blocks' states
  // one after the other (trajectory order), their energies where known at completed_.
  void save_state() {
    if (writer_) writer_->flush();
    RunState state;
    state.step = completed_;
    state.trajectory_bytes = writer_ ? writer_->flushed_size() : 0;
    for (const Block& block : blocks_) {
      state.slots.insert(state.slots.end(), block.trajectories.begin(), block.trajectories.end());
      state.q.insert(state.q.end(), block.batch.q().begin(), block.batch.q().end());
      state.p.insert(state.p.end(), block.batch.p().begin(), block.batch.p().end());
      for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
        state.energies.push_back(block.energy_step == completed_ ? block.energies[slot] : std::nan(""));
    }
    state.records = records_;
    state.evaluations = evaluations();
    save_checkpoint(checkpoint_path(), state, fingerprint_);
  }

  // Continues from `state` (load_checkpoint): each trajectory back into its fixed block, the records, and
  // trajectory.csv cut back to the checkpoint's size.
  void resume(RunState state, const std::filesystem::path& trajectory_path) {
    const std::size_t n = job_.initial.dimension;
    const std::size_t block_count = (job_.initial.count + run_block_size - 1) / run_block_size;
    std::vector<std::vector<std::size_t>> members(block_count);
    for (std::size_t slot = 0; slot < state.slots.size(); ++slot)
      members[state.slots[slot] / run_block_size].push_back(slot);
    for (const auto& slots : members) {
      Block& block = blocks_.emplace_back(job_.integrator);
      block.batch = PhaseSpaceBatch(n, slots.size());
      for (std::size_t k = 0; k < slots.size(); ++k) {
        const auto from = static_cast<std::ptrdiff_t>(slots[k] * n);
        std::copy_n(state.q.begin() + from, n, block.batch.q(k).begin());
        std::copy_n(state.p.begin() + from, n, block.batch.p(k).begin());
        block.trajectories.push_back(state.slots[slots[k]]);
        block.energies.push_back(state.energies[slots[k]]);
      }
    }
    records_ = std::move(state.records);
    completed_ = state.step;
    evaluations_before_ = state.evaluations;
    resumed_ = true;
    if (job_.every > 0) writer_.emplace(trajectory_path, n, state.trajectory_bytes);
  }

  EvaluationCounts evaluations() const {
    EvaluationCounts counts = evaluations_before_;
    for (const Block& block : blocks_) counts += block.integrator.evaluations();
    return counts;
  }

  // Runs `action(block, worker)` on every block with a state left, blocks spread over the workers' threads.
  // Exceptions are kept per block; the first in block order is rethrown after all blocks are done.
  template <class Action>
  void for_each_block(Action&& action) {
    const auto count = static_cast<std::ptrdiff_t>(blocks_.size());
#pragma omp parallel for num_threads(static_cast<int>(workers_.size())) schedule(dynamic, 1)
    for (std::ptrdiff_t index = 0; index < count; ++index) {
      Block& block = blocks_[static_cast<std::size_t>(index)];
      if (block.trajectories.empty()) continue;
      try {
        action(block, workers_[static_cast<std::size_t>(omp_get_thread_num())]);
      } catch (...) {
        block.error = std::current_exception();
      }
    }
    for (Block& block : blocks_)
      if (block.error) {
        const auto error = block.error;
        for (Block& b : blocks_) b.error = nullptr;
        std::rethrow_exception(error);
      }
  }

  std::size_t active_count() const {
    std::size_t count = 0;
    for (const Block& block : blocks_) count += block.trajectories.size();
    return count;
  }

  bool sample_step(std::uint64_t step) const {
    return writer_ && (step % job_.every == 0 || step == job_.time.steps);
  }
  bool energy_step(std::uint64_t step) const {
    return energy_available_ && (step == job_.time.steps || (job_.every > 0 && step % job_.every == 0) ||
                                 (job_.energy_every > 0 && step % job_.energy_every == 0));
  }

  // The end of the chunk starting at `from`: the next sample, energy evaluation or the last step, and at most
  // run_chunk_state_steps state-steps away.
  std::uint64_t next_event(std::uint64_t from) const {
    std::uint64_t to = job_.time.steps;
    if (job_.every > 0) to = std::min(to, (from / job_.every + 1) * job_.every);
    if (energy_available_ && job_.energy_every > 0)
      to = std::min(to, (from / job_.energy_every + 1) * job_.energy_every);
    if (job_.checkpoint.every_steps > 0)
      to = std::min(to, (from / job_.checkpoint.every_steps + 1) * job_.checkpoint.every_steps);
    const std::uint64_t longest = std::max<std::uint64_t>(1, run_chunk_state_steps / std::max<std::size_t>(1, active_count()));
    return std::min(to, from + longest);
  }

  // Every block from step `from` to `to`, then H at `to` when it is an energy step.
  void advance(std::uint64_t from, std::uint64_t to) {
    try {
      for_each_block([&](Block& block, Worker& worker) { advance_block(block, worker, from, to); });
    } catch (...) {
      for (Block& block : blocks_) {  // back to the chunk's start: the run ends at `from`
        if (!block.chunk_start_integrator) continue;
        block.batch = block.chunk_start;
        block.integrator = *block.chunk_start_integrator;
        block.departures.clear();
      }
      throw;
    }
    apply_departures();
    completed_ = to;
    if (energy_step(to)) {
      for_each_block([&](Block& block, Worker& worker) { evaluate_energies(block, worker, to); });
      apply_departures();
    }
    if (sample_step(to)) write_samples(to);
  }

  void advance_block(Block& block, Worker& worker, std::uint64_t from, std::uint64_t to) {
    block.chunk_start = block.batch;
    block.chunk_start_integrator = block.integrator;
    const bool closest = job_.analysis.closest_return_after.has_value();
    if (closest) save_closest(block);
    const double dt = job_.time.dt;
    bool clean = true;
    try {
      if (fused_ && !closest && worker.model.can_integrate()) {
        worker.model.integrate(block.integrator, block.batch, dt, to - from);
      } else {
        for (std::uint64_t step = from; step < to; ++step) {
          block.integrator.step(worker.model, block.batch, dt);
          if (closest) track_closest_return(block, step + 1);
        }
      }
    } catch (const ModelError&) {
      clean = false;
    }
    if (clean && all_finite(block.batch)) return;
    block.batch = block.chunk_start;
    block.integrator = *block.chunk_start_integrator;
    if (closest) restore_closest(block);
    for (std::uint64_t step = from + 1; step <= to && !block.trajectories.empty(); ++step) {
      checked_step(block, worker, step);
      if (closest) track_closest_return(block, step);
    }
  }

  // Updates each of the block's trajectories' closest return to its initial state, for |t| >= |closest_return_after|.
  void track_closest_return(const Block& block, std::uint64_t step) {
    const double t = job_.time.time_at(step);
    if (std::abs(t) < std::abs(*job_.analysis.closest_return_after)) return;
    const std::size_t n = job_.initial.dimension;
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      TrajectoryRecord& record = records_[block.trajectories[slot]];
      const std::size_t first = block.trajectories[slot] * n;
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double dq = block.batch.q(slot)[i] - job_.initial.q[first + i];
        const double dp = block.batch.p(slot)[i] - job_.initial.p[first + i];
        sum += dq * dq + dp * dp;
      }
      const double distance = std::sqrt(sum);
      if (!record.closest_distance || distance < *record.closest_distance) {
        record.closest_distance = distance;
        record.closest_step = step;
        record.closest_t = t;
      }
    }
  }
  void save_closest(Block& block) const {
    block.chunk_start_closest.resize(block.trajectories.size());
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      const TrajectoryRecord& record = records_[block.trajectories[slot]];
      TrajectoryRecord& saved = block.chunk_start_closest[slot];
      saved.closest_distance = record.closest_distance;
      saved.closest_step = record.closest_step;
      saved.closest_t = record.closest_t;
    }
  }
  void restore_closest(const Block& block) {
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      TrajectoryRecord& record = records_[block.trajectories[slot]];
      const TrajectoryRecord& saved = block.chunk_start_closest[slot];
      record.closest_distance = saved.closest_distance;
      record.closest_step = saved.closest_step;
      record.closest_t = saved.closest_t;
    }
  }

  // One step of the block, from `step - 1` to `step`, retiring the states that fail or diverge.
  void checked_step(Block& block, Worker& worker, std::uint64_t step) {
    const PhaseSpaceBatch before = block.batch;
    const double dt = job_.time.dt;
    std::vector<std::string> errors;
    try {
      errors = isolate_failures(block.batch, before, [&](PhaseSpaceBatch& x, std::size_t) {
        block.integrator.step(worker.model, x, dt);
      });
    } catch (...) {
      block.batch = before;
      throw;
    }
    std::vector<bool> retire(block.trajectories.size(), false);
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      Departure departure;
      if (!errors[slot].empty()) {
        departure.status = "failed";
        departure.error = "the model failed at step " + std::to_string(step) + ": " + errors[slot];
      } else if (auto variable = first_non_finite(block.batch, slot); !variable.empty()) {
        departure.status = "diverged";
        departure.variable = variable;
      } else {
        continue;
      }
      retire[slot] = true;
      departure.trajectory = block.trajectories[slot];
      departure.step = step;
      departure.final_step = step - 1;
      departure.q.assign(before.q(slot).begin(), before.q(slot).end());
      departure.p.assign(before.p(slot).begin(), before.p(slot).end());
      departure.energy = energy_of(worker, before, slot);
      block.departures.push_back(std::move(departure));
    }
    compact(block, retire);
  }

  // H of state `slot` of x alone, or nothing when unknown.
  std::optional<double> energy_of(Worker& worker, const PhaseSpaceBatch& x, std::size_t slot) const {
    if (!energy_available_) return std::nullopt;
    try {
      const double energy = worker.energy.evaluate_one(worker.model, single_state(x, slot));
      if (std::isfinite(energy)) return energy;
    } catch (const ModelError&) {
    }
    return std::nullopt;
  }

  // H of the block's states at `step`; the states the model fails on are retired as "failed". Updates the
  // records' H0 (step 0) and largest relative error (each trajectory belongs to one block: no two threads touch
  // the same record).
  void evaluate_energies(Block& block, Worker& worker, std::uint64_t step) {
    if (!energy_available_) return;
    const auto errors = compute_energies(block, worker, step);
    std::vector<bool> retire(block.trajectories.size(), false);
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      TrajectoryRecord& record = records_[block.trajectories[slot]];
      if (errors[slot].empty()) {
        if (step == 0) record.energy_initial = std::isfinite(block.energies[slot])
                                                   ? std::optional<double>(block.energies[slot])
                                                   : std::nullopt;
        if (auto error = relative_energy_error(energy_in(block, slot), record.energy_initial))
          record.max_abs_relative_error = std::max(record.max_abs_relative_error, std::abs(*error));
        continue;
      }
      retire[slot] = true;
      Departure departure;
      departure.trajectory = block.trajectories[slot];
      departure.step = departure.final_step = step;
      departure.phase = 1;
      departure.status = "failed";
      departure.error = "the energy could not be evaluated at step " + std::to_string(step) + ": " + errors[slot];
      departure.q.assign(block.batch.q(slot).begin(), block.batch.q(slot).end());
      departure.p.assign(block.batch.p(slot).begin(), block.batch.p(slot).end());
      block.departures.push_back(std::move(departure));
    }
    compact(block, retire);
  }

  // Fills block.energies at `step` (NaN where the model fails); returns the model's message per slot.
  std::vector<std::string> compute_energies(Block& block, Worker& worker, std::uint64_t step) const {
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

  std::optional<double> energy_in(const Block& block, std::size_t slot) const {
    if (!energy_available_ || !std::isfinite(block.energies[slot])) return std::nullopt;
    return block.energies[slot];
  }

  // Removes the slots marked in `retire` from the block, keeping the others in order.
  static void compact(Block& block, const std::vector<bool>& retire) {
    std::size_t kept = 0;
    for (bool r : retire) kept += r ? 0 : 1;
    if (kept == block.trajectories.size()) return;
    PhaseSpaceBatch next(block.batch.dimension(), kept);
    std::vector<std::size_t> next_trajectories;
    std::vector<double> next_energies;
    for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
      if (retire[slot]) continue;
      copy_state(block.batch, slot, next, next_trajectories.size());
      next_trajectories.push_back(block.trajectories[slot]);
      next_energies.push_back(block.energies[slot]);
    }
    block.batch = std::move(next);
    block.trajectories = std::move(next_trajectories);
    block.energies = std::move(next_energies);
  }

  // Moves the blocks' departures into the records and writes their last rows, in the order a step-by-step run
  // would have.
  void apply_departures() {
    std::vector<Departure> departures;
    for (Block& block : blocks_) {
      std::move(block.departures.begin(), block.departures.end(), std::back_inserter(departures));
      block.departures.clear();
    }
    std::sort(departures.begin(), departures.end(), [](const Departure& a, const Departure& b) {
      return std::tie(a.step, a.phase, a.trajectory) < std::tie(b.step, b.phase, b.trajectory);
    });
    for (const Departure& departure : departures) {
      TrajectoryRecord& record = records_[departure.trajectory];
      record.status = departure.status;
      record.error = departure.error;
      if (departure.status == "diverged") {
        record.diverged_step = departure.step;
        record.diverged_t = job_.time.time_at(departure.step);
        record.diverged_variable = departure.variable;
      }
      finalize(departure.trajectory, departure.final_step, departure.q, departure.p, departure.energy);
    }
  }

  void write_row(std::size_t trajectory, std::uint64_t step, std::span<const double> q, std::span<const double> p,
                 std::optional<double> energy) {
    TrajectoryRecord& record = records_[trajectory];
    if (!writer_ || record.last_written_step == step) return;
    writer_->write(trajectory, step, job_.time.time_at(step), q, p, energy,
                   relative_energy_error(energy, record.energy_initial));
    record.last_written_step = step;
  }

  void write_samples(std::uint64_t step) {
    for (const Block& block : blocks_)
      for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot)
        write_row(block.trajectories[slot], step, block.batch.q(slot), block.batch.p(slot), energy_in(block, slot));
  }

  // Records the final state of `trajectory` (at `step`, with H `energy`) and makes it the trajectory's last row.
  void finalize(std::size_t trajectory, std::uint64_t step, std::span<const double> q, std::span<const double> p,
                std::optional<double> energy) {
    TrajectoryRecord& record = records_[trajectory];
    record.final_step = step;
    record.final_t = job_.time.time_at(step);
    record.final_q.assign(q.begin(), q.end());
    record.final_p.assign(p.begin(), p.end());
    record.energy_final = energy;
    write_row(trajectory, step, q, p, energy);
  }

  // The states still active when the loop ends: completed, interrupted, or failed with the run. Their H is
  // evaluated at completed_ unless it already was; a state whose H then fails keeps a null energy.
  void finish_active() {
    if (energy_available_) {
      try {
        for_each_block([&](Block& block, Worker& worker) {
          if (block.energy_step != completed_) compute_energies(block, worker, completed_);
        });
      } catch (const std::exception& error) {
        if (run_error_.empty()) run_error_ = error.what();
      }
    }
    const std::string status = !run_error_.empty() ? "failed" : interrupted_ || completed_ < job_.time.steps
                                                                    ? "interrupted"
                                                                    : "completed";
    for (Block& block : blocks_) {
      for (std::size_t slot = 0; slot < block.trajectories.size(); ++slot) {
        TrajectoryRecord& record = records_[block.trajectories[slot]];
        record.status = status;
        if (!run_error_.empty()) record.error = run_error_;
        const bool known = block.energy_step == completed_;
        try {
          finalize(block.trajectories[slot], completed_, block.batch.q(slot), block.batch.p(slot),
                   known ? energy_in(block, slot) : std::nullopt);
        } catch (const OutputError& error) {
          if (run_error_.empty()) run_error_ = error.what();
        }
      }
      block.trajectories.clear();
    }
  }

  std::size_t count_status(const std::string& status) const {
    return static_cast<std::size_t>(std::count_if(records_.begin(), records_.end(),
                                                  [&](const TrajectoryRecord& r) { return r.status == status; }));
  }

  std::string run_status() const {
    if (interrupted_) return "interrupted";
    if (!run_error_.empty() || count_status("failed") > 0) return "failed";
    if (count_status("diverged") > 0) return "diverged";
    return "completed";
  }

  ExitStatus exit_status() const {
    const auto status = run_status();
    if (status == "completed") return ExitStatus::success;
    if (status == "interrupted") return ExitStatus::interrupted;
    return ExitStatus::run_failed;
  }

  json summary(double wall_seconds) const {
    const auto description = prototype_.describe();
    json summary;
    summary["status"] = run_status();
    if (!run_error_.empty()) summary["error"] = run_error_;
    summary["job"] = job_.file.string();
    summary["model"] = {{"plugin", plugin_.name()},
                        {"version", plugin_.version()},
                        {"path", plugin_.path().string()},
                        {"dimension", job_.initial.dimension},
                        {"parameters", json(model_.parameters())}};
    summary["hamiltonian"] = job_.integrator.form == HamiltonianForm::TTV ? "TTV" : "VVT";
    summary["integrator"] = {{"scheme", description.scheme},
                             {"order", description.order.to_string()},
                             {"t2", description.t2},
                             {"symplectic", description.symplectic},
                             {"time_reversible", description.time_reversible},
                             {"basic_steps_per_step", description.basic_steps_per_step}};
    summary["time"] = {{"dt", job_.time.dt},
                       {"dt_requested", job_.time.dt_requested},
                       {"steps", job_.time.steps},
                       {"t_end", job_.time.t_end},
                       {"steps_completed", completed_}};
    const std::string hamiltonian = job_.integrator.form == HamiltonianForm::TTV ? "H = T_i(p) V_ij(q) T_j(p)"
                                                                                  : "H = V_i(q) T_ij(p) V_j(q)";
    if (energy_available_)
      summary["energy"] = {{"available", true},
                           {"hamiltonian", hamiltonian},
                           {"relative_error", "(H - H0) / H0; null when H0 = 0"},
                           {"relative_error_max_abs", energy_steps_text()}};
    else
      summary["energy"] = {{"available", false},
                           {"hamiltonian", hamiltonian},
                           {"reason", "the plugin '" + plugin_.name() +
                                          "' provides no Hessians (hessian_T and hessian_V), which " + hamiltonian +
                                          " needs"}};
    summary["output"] = {{"directory", options_.output_directory.string()},
                         {"trajectory", writer_ ? json("trajectory.csv") : json(nullptr)},
                         {"every", job_.every},
                         {"energy_every", job_.energy_every}};
    summary["trajectories"] = nullptr;  // the entries: write_summary_json, from records_
    summary["counts"] = {{"completed", count_status("completed")},
                         {"diverged", count_status("diverged")},
                         {"failed", count_status("failed")},
                         {"interrupted", count_status("interrupted")}};
    const auto evaluations = this->evaluations();
    summary["evaluations"] = {{"grad_T", evaluations.grad_T}, {"grad_V", evaluations.grad_V}};
    summary["wall_seconds"] = wall_seconds;
    return summary;
  }

  std::string energy_steps_text() const {
    return "over the steps where H was evaluated: 0, every written sample (output.every), " +
           (job_.energy_every > 0 ? "every " + std::to_string(job_.energy_every) + "-th step (output.energy_every), "
                                  : std::string()) +
           "the last step, and the final state of a trajectory that stopped early";
  }

  const Job& job_;
  const Plugin& plugin_;
  const PluginModel& model_;
  const RunOptions& options_;
  Integrator prototype_;  // describes the scheme; the blocks step with their own copies
  bool fused_;             // unchecked chunks through the plugin's integrate() when it has one (RunOptions::fused)
  bool energy_available_;
  std::vector<TrajectoryRecord> records_;
  std::vector<Block> blocks_;
  std::vector<Worker> workers_;  // one per thread
  std::optional<TrajectoryWriter> writer_;
  std::uint64_t completed_ = 0;
  bool interrupted_ = false;
  bool resumed_ = false;
  EvaluationCounts evaluations_before_;  // counted before the checkpoint a resumed run started from
  std::string fingerprint_;             // job_fingerprint, for checkpoints
  std::string run_error_;
};

}  // namespace

RunOutcome run_job(const LoadedJob& job, const RunOptions& options) { return Run(job, options).execute(); }

}  // namespace nonsep::host
