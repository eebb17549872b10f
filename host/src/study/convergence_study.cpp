#include "nonsep/host/study/convergence_study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/formula/formula_model.hpp"
#include "nonsep/host/json/finite_or_null.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/output/run_folder.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"

namespace nonsep::host {

using nlohmann::ordered_json;

namespace {

using Clock = std::chrono::steady_clock;

class StudyExecution {
 public:
  StudyExecution(const LoadedJob& loaded, const RunOptions& options)
      : loaded_(loaded),
        job_(loaded.job),
        study_(loaded.job.study()),
        options_(options),
        folder_(options.output_directory, "study", loaded.job.file, folder_use(options)),
        energy_available_(loaded.plugin.has_hessians()),
        csv_(options.output_directory / "convergence.csv",
             "integrator,scheme,order,t2,symplectic,dt,steps,basic_steps,grad_T,grad_V,relative_energy_error,"
             "phase_error,status,family,grad_H,max_abs_relative_energy_error"),
        work_precision_csv_(options.output_directory / "work_precision.csv",
                            "integrator,scheme,family,options,order,symplectic,dt,steps,evaluations,grad_T,grad_V,"
                            "grad_H,wall_seconds,repeats,relative_energy_error,phase_error,status,"
                            "max_abs_relative_energy_error") {}
  StudyExecution(const StudyExecution&) = delete;
  StudyExecution& operator=(const StudyExecution&) = delete;

  StudyOutcome execute() {
    const auto start = Clock::now();
    try {
      if (study_.reference_run) compute_reference(*study_.reference_run);
      for (const auto& integrator : study_.integrators) {
        runs_.emplace_back();
        for (const std::uint64_t steps : integrator.steps) {
          if (interrupted_) break;
          runs_.back().push_back(run_one(integrator, steps));
          if (runs_.back().back().status != TrajectoryStatus::interrupted) write_row(integrator, runs_.back().back());
        }
      }
    } catch (const std::exception& error) {
      run_error_ = error.what();
    }
    try {
      csv_.flush();
      work_precision_csv_.flush();
    } catch (const OutputError& error) {
      if (run_error_.empty()) run_error_ = error.what();
    }
    StudyOutcome outcome;
    outcome.status = status();
    outcome.exit_status = outcome.status == TrajectoryStatus::completed     ? ExitStatus::success
                          : outcome.status == TrajectoryStatus::interrupted ? ExitStatus::interrupted
                                                                            : ExitStatus::run_failed;
    outcome.error = run_error_;
    for (const auto& list : runs_)
      for (const auto& run : list) ++outcome.run_counts[run.status];
    for (std::size_t i = 0; i < runs_.size(); ++i)
      outcome.fits.push_back(fit_study(study_.integrators[i], Integrator::describe(study_.integrators[i].spec),
                                       runs_[i], !reference_q_.empty(), reference_length()));
    outcome.runs = std::move(runs_);
    outcome.summary = summary(outcome, std::chrono::duration<double>(Clock::now() - start).count());
    try {
      write_file_atomically(options_.output_directory / "summary.json", outcome.summary.dump(2) + "\n");
    } catch (const OutputError& error) {
      outcome.error = (run_error_.empty() ? "" : run_error_ + "; ") + error.what();
      outcome.summary["error"] = outcome.error;
      if (outcome.exit_status == ExitStatus::success) outcome.exit_status = ExitStatus::run_failed;
    }
    return outcome;
  }

 private:
  // Runs /study/reference_run; its end state becomes the reference (throws when it does not complete).
  void compute_reference(const StudyIntegrator& reference) {
    const std::uint64_t steps = reference.steps.front();
    const TimeGrid time = TimeGrid::to_end(study_.t_end, study_.t_end / static_cast<double>(steps), steps);
    EnsembleDriver driver(
        loaded_.plugin, loaded_.model,
        {reference.spec, time, job_.initial.dimension, job_.initial.q, job_.initial.p, 1, options_.stop_requested});
    if (driver.run() != DriverEnd::completed || driver.records().front().status != TrajectoryStatus::completed)
      throw std::runtime_error(
          "the reference run (/study/reference_run, " + reference.spec.scheme + " with " + std::to_string(steps) +
          " steps) did not complete: " + (driver.error().empty() ? driver.records().front().message : driver.error()));
    reference_q_ = driver.records().front().final_q;
    reference_p_ = driver.records().front().final_p;
  }

  StudyRun run_one(const StudyIntegrator& study_integrator, std::uint64_t steps) {
    StudyRun run;
    run.steps = steps;
    const TimeGrid time = TimeGrid::to_end(study_.t_end, study_.t_end / static_cast<double>(steps), steps);
    run.dt = time.dt;
    run.basic_steps = steps * Integrator::describe(study_integrator.spec).basic_steps_per_step;
    // The timed runs (study.repeats of them) evaluate H only at step 0 and the last step, as a plain run does; one
    // more run, not timed, evaluates it at every step for the largest |dH/H0| over the run (a symplectic scheme's
    // energy error oscillates, so its value at t_end may be far below the maximum). Its numbers are those of the
    // timed runs bit for bit: the energy observer does not change the steps.
    const EnsembleSetup setup{study_integrator.spec, time, job_.initial.dimension, job_.initial.q,
                              job_.initial.p,        1,    options_.stop_requested};
    std::vector<double> seconds;
    for (int r = 0; r < study_.repeats && !interrupted_; ++r) {
      EnsembleDriver timed(loaded_.plugin, loaded_.model, setup);
      const auto start = Clock::now();
      if (timed.run() != DriverEnd::completed) break;
      seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
      run.evaluations = timed.evaluations();
    }
    EnsembleDriver driver(loaded_.plugin, loaded_.model, setup);
    EnergyErrorObserver energy_every_step(1, 1, std::nullopt);
    if (energy_available_) driver.add_observer(energy_every_step);
    const DriverEnd end = driver.run();
    if (seconds.empty()) seconds.push_back(std::nan(""));
    std::sort(seconds.begin(), seconds.end());
    const std::size_t middle = seconds.size() / 2;
    run.wall_seconds = seconds.size() % 2 ? seconds[middle] : (seconds[middle - 1] + seconds[middle]) / 2.0;
    run.repeats = static_cast<int>(seconds.size());
    if (run.evaluations.grad_T + run.evaluations.grad_V + run.evaluations.grad_H == 0)
      run.evaluations = driver.evaluations();
    const TrajectoryRecord& record = driver.records().front();
    if (!energy_initial_) energy_initial_ = record.energy_initial;
    if (end == DriverEnd::failed) throw std::runtime_error(driver.error());
    if (end == DriverEnd::interrupted) interrupted_ = true;
    run.status = record.status;
    if (record.status == TrajectoryStatus::diverged)
      run.error = record.stop_variable + " is not finite after step " + std::to_string(record.stop_step);
    else
      run.error = record.message;
    if (record.status != TrajectoryStatus::completed) return run;
    run.relative_energy_error = relative_energy_error(record.energy_final, record.energy_initial);
    run.max_abs_relative_energy_error = energy_every_step.max_abs(0);
    if (!reference_q_.empty()) {
      double sum = 0.0;
      for (std::size_t i = 0; i < record.final_q.size(); ++i) {
        const double dq = record.final_q[i] - reference_q_[i], dp = record.final_p[i] - reference_p_[i];
        sum += dq * dq + dp * dp;
      }
      run.phase_error = std::sqrt(sum);
    }
    return run;
  }

  void write_row(const StudyIntegrator& integrator, const StudyRun& run) {
    const auto description = Integrator::describe(integrator.spec);
    std::string& row = csv_.row();
    append_csv_text(row, integrator.label);
    row += "," + description.scheme + "," + description.order.to_string() + ",";
    append_number(row, description.t2);
    row += description.symplectic ? ",true," : ",false,";
    append_number(row, run.dt);
    row += "," + std::to_string(run.steps) + "," + std::to_string(run.basic_steps) + "," +
           std::to_string(run.evaluations.grad_T) + "," + std::to_string(run.evaluations.grad_V) + ",";
    if (run.relative_energy_error) append_number(row, *run.relative_energy_error);
    row += ",";
    if (run.phase_error) append_number(row, *run.phase_error);
    row += ",";
    row += to_string(run.status);
    row += "," + description.family + "," + std::to_string(run.evaluations.grad_H);
    append_csv_number(row.append(","), run.max_abs_relative_energy_error);
    csv_.end_row();
    write_work_precision_row(integrator, description, run);
  }

  // work_precision.csv: the cost (evaluations = grad_T + grad_V + grad_H + grad_K + grad_U, each counted once per
  // state, the last two zero without a separable part; a grad_H costs the model a gradient, two Hessians and a
  // third-derivative contraction) and the median wall time against
  // the errors.
  void write_work_precision_row(const StudyIntegrator& integrator, const IntegratorDescription& description,
                                const StudyRun& run) {
    const EvaluationCounts& e = run.evaluations;
    std::string& row = work_precision_csv_.row();
    append_csv_text(row, integrator.label);
    row += "," + description.scheme + "," + description.family + ",";
    append_csv_text(row, options_text(integrator.spec));
    row += "," + description.order.to_string() + (description.symplectic ? ",true," : ",false,");
    append_number(row, run.dt);
    row += "," + std::to_string(run.steps) + "," +
           std::to_string(e.grad_T + e.grad_V + e.grad_H + e.grad_K + e.grad_U) + "," + std::to_string(e.grad_T) + "," +
           std::to_string(e.grad_V) + "," + std::to_string(e.grad_H) + ",";
    append_number(row, run.wall_seconds);
    row += "," + std::to_string(run.repeats) + ",";
    if (run.relative_energy_error) append_number(row, *run.relative_energy_error);
    row += ",";
    if (run.phase_error) append_number(row, *run.phase_error);
    row += ",";
    row += to_string(run.status);
    append_csv_number(row.append(","), run.max_abs_relative_energy_error);
    work_precision_csv_.end_row();
  }

  // The scheme's catalogue options with their values: "order=4/3 t2=-1.81712059283214", "omega=20".
  static std::string options_text(const IntegratorSpec& spec) {
    std::string text;
    const Scheme* scheme = find_scheme(spec.scheme);
    for (const auto& parameter : scheme ? scheme->parameters : std::vector<ParameterDescription>{}) {
      std::string value;
      const auto option = option_value(spec, parameter);
      if (const auto* order = std::get_if<Fraction>(&option))
        value = order->to_string();
      else
        append_number(value, std::get<double>(option));
      text += (text.empty() ? "" : " ") + parameter.name + "=" + value;
    }
    return text;
  }

  // |(q, p)_ref|, at least 1: the scale of the phase errors.
  double reference_length() const {
    double sum = 0.0;
    for (std::size_t i = 0; i < reference_q_.size(); ++i)
      sum += reference_q_[i] * reference_q_[i] + reference_p_[i] * reference_p_[i];
    return std::max(1.0, std::sqrt(sum));
  }

  TrajectoryStatus status() const {
    if (interrupted_) return TrajectoryStatus::interrupted;
    const auto any = [&](TrajectoryStatus status) {
      for (const auto& list : runs_)
        for (const auto& run : list)
          if (run.status == status) return true;
      return false;
    };
    if (!run_error_.empty() || any(TrajectoryStatus::failed)) return TrajectoryStatus::failed;
    if (any(TrajectoryStatus::diverged)) return TrajectoryStatus::diverged;
    return TrajectoryStatus::completed;
  }

  ordered_json summary(const StudyOutcome& outcome, double wall_seconds) const {
    ordered_json summary;
    summary["status"] = to_string(outcome.status);
    if (!run_error_.empty()) summary["error"] = run_error_;
    summary["job"] = job_.file.string();
    summary["model"] = {{"plugin", loaded_.plugin.name()},
                        {"version", loaded_.plugin.version()},
                        {"path", loaded_.plugin.path().string()},
                        {"dimension", job_.initial.dimension},
                        {"parameters", ordered_json(loaded_.model.parameters())}};
    if (job_.formula) summary["model"]["formula"] = formula::formula_record(*job_.formula, job_.formula_cache_key);
    summary["hamiltonian"] = hamiltonian_name(loaded_.plugin, study_.form);
    ordered_json study;
    study["t_end"] = study_.t_end;
    study["initial"] = {{"q", job_.initial.q}, {"p", job_.initial.p}};
    study["reference"] =
        reference_q_.empty() ? ordered_json(nullptr) : ordered_json{{"q", reference_q_}, {"p", reference_p_}};
    if (study_.reference_run)
      study["reference_from"] = {{"scheme", study_.reference_run->spec.scheme},
                                 {"options", options_text(study_.reference_run->spec)},
                                 {"steps", study_.reference_run->steps.front()}};
    study["energy_initial"] = finite_or_null(energy_initial_);
    study["energy_available"] = energy_available_;
    const StatusCounts& counts = outcome.run_counts;
    study["runs"] = {{"completed", counts.completed},
                     {"diverged", counts.diverged},
                     {"failed", counts.failed},
                     {"interrupted", counts.interrupted}};
    summary["study"] = std::move(study);
    ordered_json fits = ordered_json::array();
    ordered_json failures = ordered_json::array();
    for (std::size_t i = 0; i < outcome.fits.size(); ++i) {
      fits.push_back(to_json(outcome.fits[i]));
      for (const auto& run : outcome.runs[i])
        if (run.status == TrajectoryStatus::diverged || run.status == TrajectoryStatus::failed)
          failures.push_back({{"integrator", outcome.fits[i].integrator},
                              {"steps", run.steps},
                              {"status", to_string(run.status)},
                              {"error", run.error}});
    }
    summary["fits"] = std::move(fits);
    if (!failures.empty()) summary["failures"] = std::move(failures);
    summary["output"] = {{"directory", options_.output_directory.string()},
                         {"convergence", "convergence.csv"},
                         {"work_precision", "work_precision.csv"}};
    summary["study"]["repeats"] = study_.repeats;
    summary["wall_seconds"] = wall_seconds;
    return summary;
  }

  const LoadedJob& loaded_;
  const Job& job_;
  const Study& study_;
  const RunOptions& options_;
  const RunFolder folder_;
  bool energy_available_;
  std::optional<double> energy_initial_;
  CsvAppender csv_;
  CsvAppender work_precision_csv_;
  std::vector<double> reference_q_ = study_.reference_q, reference_p_ = study_.reference_p;
  std::vector<std::vector<StudyRun>> runs_;  // per integrator, in step order
  bool interrupted_ = false;
  std::string run_error_;
};

}  // namespace

StudyOutcome run_study(const LoadedJob& job, const RunOptions& options) {
  return StudyExecution(job, options).execute();
}

}  // namespace nonsep::host
