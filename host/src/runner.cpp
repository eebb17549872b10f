#include "nonsep/host/runner.hpp"

#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/core/energy.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/host/checkpoint.hpp"
#include "nonsep/host/output_files.hpp"
#include "nonsep/host/progress_bar.hpp"

namespace nonsep::host {

using json = nlohmann::ordered_json;

namespace {

using Clock = std::chrono::steady_clock;

std::optional<double> relative_error(std::optional<double> energy, std::optional<double> initial) {
  if (!energy || !initial || *initial == 0.0) return std::nullopt;
  return (*energy - *initial) / *initial;
}

json optional_number(std::optional<double> value) {
  return value && std::isfinite(*value) ? json(*value) : json(nullptr);
}

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

class Run {
 public:
  Run(const LoadedJob& loaded, const RunOptions& options)
      : job_(loaded.job),
        plugin_(loaded.plugin),
        model_(loaded.model),
        options_(options),
        integrator_(job_.integrator),
        energy_available_(loaded.plugin.has_hessians()),
        energy_(job_.integrator.form),
        records_(job_.initial.count),
        batch_(job_.initial.dimension, job_.initial.count),
        slots_(job_.initial.count) {
    fingerprint_ = job_fingerprint(loaded);
    std::error_code error;
    std::filesystem::create_directories(options.output_directory, error);
    if (error)
      throw OutputError("cannot create the output folder " + options.output_directory.string() + ": " +
                        error.message());
    const auto trajectory_path = options.output_directory / "trajectory.csv";
    if (options.resume) {
      resume(load_checkpoint(checkpoint_path(), loaded), trajectory_path);
      return;
    }
    if (job_.every > 0)
      writer_.emplace(trajectory_path, job_.initial.dimension);
    else
      std::filesystem::remove(trajectory_path, error);  // a file from an earlier run would mislead
    std::copy(job_.initial.q.begin(), job_.initial.q.end(), batch_.q().begin());
    std::copy(job_.initial.p.begin(), job_.initial.p.end(), batch_.p().begin());
    std::iota(slots_.begin(), slots_.end(), std::size_t{0});
    energies_.assign(slots_.size(), std::nan(""));
  }

  RunOutcome execute() {
    const auto start = Clock::now();
    ProgressBar progress(options_.show_progress, job_.time.steps);
    auto next_flush = start + std::chrono::seconds(1);
    const auto checkpoint_interval = std::chrono::duration<double>(job_.checkpoint.every_seconds);
    auto next_checkpoint = start + std::chrono::duration_cast<Clock::duration>(checkpoint_interval);
    try {
      if (!resumed_) {
        const auto energy_errors = evaluate_energies();
        for (std::size_t slot = 0; slot < slots_.size(); ++slot)
          records_[slots_[slot]].energy_initial = energy_at(slot);
        retire_energy_failures(energy_errors, 0);
        write_samples(0);
      }
      while (completed_ < job_.time.steps && !slots_.empty()) {
        if (options_.stop_requested && options_.stop_requested->load()) {
          interrupted_ = true;
          break;
        }
        advance(completed_ + 1);
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
        progress.update(completed_, job_.time.time_at(completed_), slots_.size());
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
      write_file_atomically(options_.output_directory / "summary.json", outcome.summary.dump(2) + "\n");
    } catch (const OutputError& error) {
      outcome.summary["error"] = (run_error_.empty() ? "" : run_error_ + "; ") + error.what();
      if (outcome.exit_status == ExitStatus::success) outcome.exit_status = ExitStatus::run_failed;
    }
    return outcome;
  }

 private:
  std::filesystem::path checkpoint_path() const { return options_.output_directory / checkpoint_file_name; }

  // Flushes trajectory.csv and saves checkpoint.json for the state after step completed_.
  void save_state() {
    if (writer_) writer_->flush();
    RunState state;
    state.step = completed_;
    state.trajectory_bytes = writer_ ? writer_->flushed_size() : 0;
    state.slots = slots_;
    state.q.assign(batch_.q().begin(), batch_.q().end());
    state.p.assign(batch_.p().begin(), batch_.p().end());
    state.energies = energies_;
    state.records = records_;
    state.evaluations = evaluations();
    save_checkpoint(checkpoint_path(), state, fingerprint_);
  }

  // Continues from `state` (load_checkpoint): the batch, the records, and trajectory.csv cut back to the
  // checkpoint's size.
  void resume(RunState state, const std::filesystem::path& trajectory_path) {
    const std::size_t n = job_.initial.dimension;
    batch_ = PhaseSpaceBatch(n, state.slots.size());
    std::copy(state.q.begin(), state.q.end(), batch_.q().begin());
    std::copy(state.p.begin(), state.p.end(), batch_.p().begin());
    slots_ = std::move(state.slots);
    energies_ = std::move(state.energies);
    records_ = std::move(state.records);
    completed_ = state.step;
    evaluations_before_ = state.evaluations;
    resumed_ = true;
    if (job_.every > 0) writer_.emplace(trajectory_path, n, state.trajectory_bytes);
  }

  EvaluationCounts evaluations() const {
    EvaluationCounts counts = evaluations_before_;
    counts += integrator_.evaluations();
    return counts;
  }

  // One step of every active state, from `step - 1` to `step`.
  void advance(std::uint64_t step) {
    const PhaseSpaceBatch before = batch_;
    const std::vector<double> energies_before = energies_;
    const double dt = job_.time.dt;
    std::vector<std::string> errors;
    try {
      errors = isolate_failures(batch_, before,
                                [&](PhaseSpaceBatch& x, std::size_t) { integrator_.step(model_, x, dt); });
    } catch (...) {
      batch_ = before;
      throw;
    }
    std::vector<bool> retire(slots_.size(), false);
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      TrajectoryRecord& record = records_[slots_[slot]];
      if (!errors[slot].empty()) {
        record.status = "failed";
        record.error = "the model failed at step " + std::to_string(step) + ": " + errors[slot];
      } else if (auto variable = first_non_finite(batch_, slot); !variable.empty()) {
        record.status = "diverged";
        record.diverged_step = step;
        record.diverged_t = job_.time.time_at(step);
        record.diverged_variable = variable;
      } else {
        continue;
      }
      retire[slot] = true;
      finalize(slot, before, energies_before, step - 1);
    }
    compact(retire);
    completed_ = step;
    retire_energy_failures(evaluate_energies(), step);
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      TrajectoryRecord& record = records_[slots_[slot]];
      if (auto error = relative_error(energy_at(slot), record.energy_initial))
        record.max_abs_relative_error = std::max(record.max_abs_relative_error, std::abs(*error));
    }
    if (job_.analysis.closest_return_after) track_closest_return(step);
    if (writer_ && (step % job_.every == 0 || step == job_.time.steps)) write_samples(step);
  }

  // Updates each active trajectory's closest return to its initial state, for |t| >= |closest_return_after|.
  void track_closest_return(std::uint64_t step) {
    const double t = job_.time.time_at(step);
    if (std::abs(t) < std::abs(*job_.analysis.closest_return_after)) return;
    const std::size_t n = job_.initial.dimension;
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      TrajectoryRecord& record = records_[slots_[slot]];
      const std::size_t first = slots_[slot] * n;
      double sum = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        const double dq = batch_.q(slot)[i] - job_.initial.q[first + i];
        const double dp = batch_.p(slot)[i] - job_.initial.p[first + i];
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

  // Energies of the active states (NaN where unknown); returns the model's message per slot for those it failed on.
  std::vector<std::string> evaluate_energies() {
    energies_.assign(slots_.size(), std::nan(""));
    if (!energy_available_ || slots_.empty()) return std::vector<std::string>(slots_.size());
    PhaseSpaceBatch x = batch_;
    auto errors = isolate_failures(x, batch_, [&](PhaseSpaceBatch& part, std::size_t first) {
      energy_.evaluate(model_, part, std::span<double>(energies_).subspan(first, part.count()));
    });
    for (std::size_t slot = 0; slot < slots_.size(); ++slot)
      if (!errors[slot].empty()) energies_[slot] = std::nan("");
    return errors;
  }

  // Retires, with status "failed" at `step`, the states whose energy the model could not evaluate.
  void retire_energy_failures(const std::vector<std::string>& errors, std::uint64_t step) {
    std::vector<bool> retire(slots_.size(), false);
    bool any = false;
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      if (errors[slot].empty()) continue;
      TrajectoryRecord& record = records_[slots_[slot]];
      record.status = "failed";
      record.error = "the energy could not be evaluated at step " + std::to_string(step) + ": " + errors[slot];
      retire[slot] = any = true;
      finalize(slot, batch_, energies_, step);
    }
    if (any) compact(retire);
  }

  std::optional<double> energy_at(std::size_t slot) const {
    if (!energy_available_ || !std::isfinite(energies_[slot])) return std::nullopt;
    return energies_[slot];
  }

  void write_row(std::size_t trajectory, std::uint64_t step, const PhaseSpaceBatch& x, std::size_t slot,
                 std::optional<double> energy) {
    TrajectoryRecord& record = records_[trajectory];
    if (!writer_ || record.last_written_step == step) return;
    writer_->write(trajectory, step, job_.time.time_at(step), x.q(slot), x.p(slot), energy,
                   relative_error(energy, record.energy_initial));
    record.last_written_step = step;
  }

  void write_samples(std::uint64_t step) {
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) write_row(slots_[slot], step, batch_, slot, energy_at(slot));
  }

  // Records the final state of slot `slot` as `x`'s state `slot` at `step`, with energy `energies[slot]`, and
  // makes it the trajectory's last row.
  void finalize(std::size_t slot, const PhaseSpaceBatch& x, const std::vector<double>& energies, std::uint64_t step) {
    const std::size_t trajectory = slots_[slot];
    TrajectoryRecord& record = records_[trajectory];
    record.final_step = step;
    record.final_t = job_.time.time_at(step);
    record.final_q.assign(x.q(slot).begin(), x.q(slot).end());
    record.final_p.assign(x.p(slot).begin(), x.p(slot).end());
    std::optional<double> energy;
    if (energy_available_ && std::isfinite(energies[slot])) energy = energies[slot];
    record.energy_final = energy;
    write_row(trajectory, step, x, slot, energy);
  }

  // Removes the slots marked in `retire` from the batch, keeping the others in order.
  void compact(const std::vector<bool>& retire) {
    std::size_t kept = 0;
    for (bool r : retire) kept += r ? 0 : 1;
    if (kept == slots_.size()) return;
    PhaseSpaceBatch next(batch_.dimension(), kept);
    std::vector<std::size_t> next_slots;
    std::vector<double> next_energies;
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      if (retire[slot]) continue;
      copy_state(batch_, slot, next, next_slots.size());
      next_slots.push_back(slots_[slot]);
      next_energies.push_back(energies_[slot]);
    }
    batch_ = std::move(next);
    slots_ = std::move(next_slots);
    energies_ = std::move(next_energies);
  }

  // The states still active when the loop ends: completed, interrupted, or failed with the run.
  void finish_active() {
    const std::string status = !run_error_.empty() ? "failed" : interrupted_ || completed_ < job_.time.steps
                                                                    ? "interrupted"
                                                                    : "completed";
    for (std::size_t slot = 0; slot < slots_.size(); ++slot) {
      TrajectoryRecord& record = records_[slots_[slot]];
      record.status = status;
      if (!run_error_.empty()) record.error = run_error_;
      try {
        finalize(slot, batch_, energies_, completed_);
      } catch (const OutputError& error) {
        if (run_error_.empty()) run_error_ = error.what();
      }
    }
    slots_.clear();
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
    const auto description = integrator_.describe();
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
                           {"relative_error_max_abs", "over every step, not only the sampled ones"}};
    else
      summary["energy"] = {{"available", false},
                           {"hamiltonian", hamiltonian},
                           {"reason", "the plugin '" + plugin_.name() +
                                          "' provides no Hessians (hessian_T and hessian_V), which " + hamiltonian +
                                          " needs"}};
    summary["output"] = {{"directory", options_.output_directory.string()},
                         {"trajectory", writer_ ? json("trajectory.csv") : json(nullptr)},
                         {"every", job_.every}};
    json trajectories = json::array();
    const std::size_t n = job_.initial.dimension;
    for (std::size_t index = 0; index < records_.size(); ++index) {
      const TrajectoryRecord& record = records_[index];
      json entry;
      entry["index"] = index;
      entry["status"] = record.status;
      const auto q0 = job_.initial.q.begin() + static_cast<std::ptrdiff_t>(index * n);
      const auto p0 = job_.initial.p.begin() + static_cast<std::ptrdiff_t>(index * n);
      entry["initial"] = {{"q", std::vector<double>(q0, q0 + static_cast<std::ptrdiff_t>(n))},
                          {"p", std::vector<double>(p0, p0 + static_cast<std::ptrdiff_t>(n))}};
      entry["final"] = {{"t", record.final_t}, {"step", record.final_step}, {"q", record.final_q}, {"p", record.final_p}};
      const bool relative_known = record.energy_initial && *record.energy_initial != 0.0;
      entry["energy"] = {
          {"initial", optional_number(record.energy_initial)},
          {"final", optional_number(record.energy_final)},
          {"relative_error_final", optional_number(relative_error(record.energy_final, record.energy_initial))},
          {"relative_error_max_abs", relative_known ? json(record.max_abs_relative_error) : json(nullptr)}};
      if (record.status == "diverged")
        entry["diverged"] = {{"step", record.diverged_step}, {"t", record.diverged_t}, {"variable", record.diverged_variable}};
      if (!record.error.empty()) entry["error"] = record.error;
      if (job_.analysis.closest_return_after)
        entry["closest_return"] = record.closest_distance ? json{{"distance", *record.closest_distance},
                                                                 {"t", record.closest_t},
                                                                 {"step", record.closest_step}}
                                                          : json(nullptr);
      trajectories.push_back(std::move(entry));
    }
    summary["trajectories"] = std::move(trajectories);
    summary["counts"] = {{"completed", count_status("completed")},
                         {"diverged", count_status("diverged")},
                         {"failed", count_status("failed")},
                         {"interrupted", count_status("interrupted")}};
    const auto evaluations = this->evaluations();
    summary["evaluations"] = {{"grad_T", evaluations.grad_T}, {"grad_V", evaluations.grad_V}};
    summary["wall_seconds"] = wall_seconds;
    return summary;
  }

  const Job& job_;
  const Plugin& plugin_;
  const PluginModel& model_;
  const RunOptions& options_;
  Integrator integrator_;
  bool energy_available_;
  EnergyEvaluator energy_;
  std::vector<TrajectoryRecord> records_;
  PhaseSpaceBatch batch_;
  std::vector<std::size_t> slots_;  // slot in batch_ -> trajectory index
  std::vector<double> energies_;    // per slot, at the last completed step (NaN when unknown)
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
