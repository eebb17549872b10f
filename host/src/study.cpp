#include "nonsep/host/study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "nonsep/core/energy.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/output/files.hpp"
#include "nonsep/host/output/run_folder.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"

namespace nonsep::host {

using json = nlohmann::ordered_json;

std::optional<PowerLawFit> fit_power_law(std::span<const double> dt, std::span<const double> error) {
  std::vector<double> x, y;
  for (std::size_t i = 0; i < dt.size() && i < error.size(); ++i) {
    if (!std::isfinite(error[i]) || error[i] == 0.0 || dt[i] == 0.0 || !std::isfinite(dt[i])) continue;
    x.push_back(std::log(std::abs(dt[i])));
    y.push_back(std::log(std::abs(error[i])));
  }
  if (x.size() < 2) return std::nullopt;
  const double n = static_cast<double>(x.size());
  double mean_x = 0.0, mean_y = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mean_x += x[i] / n;
    mean_y += y[i] / n;
  }
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mean_x) * (x[i] - mean_x);
    sxy += (x[i] - mean_x) * (y[i] - mean_y);
  }
  if (sxx == 0.0) return std::nullopt;
  PowerLawFit fit;
  fit.exponent = sxy / sxx;
  fit.constant = std::exp(mean_y - fit.exponent * mean_x);
  fit.points = x.size();
  return fit;
}

namespace {

using Clock = std::chrono::steady_clock;

struct StudyRun {
  std::uint64_t steps = 0;
  double dt = 0.0;
  std::string status = "completed";
  std::string error;
  std::uint64_t basic_steps = 0;
  EvaluationCounts evaluations;
  std::optional<double> relative_energy_error, phase_error;
  std::vector<double> final_q, final_p;
};

// c of error = c dt^n with n fixed: the geometric mean of |error| / |dt|^n over the usable points.
double constant_at(double exponent, const std::vector<double>& dt, const std::vector<double>& error) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < dt.size(); ++i) {
    if (!std::isfinite(error[i]) || error[i] == 0.0 || dt[i] == 0.0) continue;
    sum += std::log(std::abs(error[i])) - exponent * std::log(std::abs(dt[i]));
    ++count;
  }
  return count ? std::exp(sum / static_cast<double>(count)) : std::nan("");
}

json optional_number(std::optional<double> value) {
  return value && std::isfinite(*value) ? json(*value) : json(nullptr);
}

class StudyExecution {
 public:
  StudyExecution(const LoadedJob& loaded, const RunOptions& options)
      : loaded_(loaded), job_(loaded.job), study_(*loaded.job.study), options_(options),
        folder_(options.output_directory, "study", loaded.job.file, folder_use(options)),
        energy_available_(loaded.plugin.has_hessians()),
        csv_(options.output_directory / "convergence.csv",
             "integrator,scheme,order,t2,symplectic,dt,steps,basic_steps,grad_T,grad_V,relative_energy_error,"
             "phase_error,status") {}
  StudyExecution(const StudyExecution&) = delete;
  StudyExecution& operator=(const StudyExecution&) = delete;

  RunOutcome execute() {
    const auto start = Clock::now();
    try {
      for (const auto& integrator : study_.integrators) {
        runs_.emplace_back();
        for (const std::uint64_t steps : integrator.steps) {
          if (interrupted_) break;
          runs_.back().push_back(run_one(integrator, steps));
          if (runs_.back().back().status != "interrupted") write_row(integrator, runs_.back().back());
        }
      }
    } catch (const std::exception& error) {
      run_error_ = error.what();
    }
    try {
      csv_.flush();
    } catch (const OutputError& error) {
      if (run_error_.empty()) run_error_ = error.what();
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
  StudyRun run_one(const StudyIntegrator& study_integrator, std::uint64_t steps) {
    StudyRun run;
    run.steps = steps;
    const TimeGrid time = TimeGrid::to_end(job_.time.t_end, job_.time.t_end / static_cast<double>(steps), steps);
    run.dt = time.dt;
    run.basic_steps = steps * Integrator(study_integrator.spec).describe().basic_steps_per_step;
    EnsembleDriver driver(loaded_.plugin, loaded_.model,
                          {study_integrator.spec, time, job_.initial.dimension, job_.initial.q, job_.initial.p, 1,
                           options_.stop_requested});
    const DriverEnd end = driver.run();
    run.evaluations = driver.evaluations();
    const TrajectoryRecord& record = driver.records().front();
    if (!energy_initial_) energy_initial_ = record.energy_initial;
    if (end == DriverEnd::failed) throw std::runtime_error(driver.error());
    if (end == DriverEnd::interrupted) interrupted_ = true;
    run.status = std::string(to_string(record.status));
    if (record.status == TrajectoryStatus::diverged)
      run.error = record.stop_variable + " is not finite after step " + std::to_string(record.stop_step);
    else
      run.error = record.message;
    if (record.status != TrajectoryStatus::completed) return run;
    run.final_q = record.final_q;
    run.final_p = record.final_p;
    run.relative_energy_error = relative_energy_error(record.energy_final, record.energy_initial);
    if (!study_.reference_q.empty()) {
      double sum = 0.0;
      for (std::size_t i = 0; i < run.final_q.size(); ++i) {
        const double dq = run.final_q[i] - study_.reference_q[i], dp = run.final_p[i] - study_.reference_p[i];
        sum += dq * dq + dp * dp;
      }
      run.phase_error = std::sqrt(sum);
    }
    return run;
  }

  void write_row(const StudyIntegrator& integrator, const StudyRun& run) {
    const auto description = Integrator(integrator.spec).describe();
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
    row += "," + run.status;
    csv_.end_row();
  }

  json fit_entry(const StudyIntegrator& integrator, const std::vector<StudyRun>& runs) const {
    const auto description = Integrator(integrator.spec).describe();
    std::vector<double> dts, energy_errors, phase_errors;
    std::vector<std::uint64_t> steps;
    int positive = 0, negative = 0;
    for (const auto& run : runs) {
      if (run.status != "completed") continue;
      dts.push_back(run.dt);
      steps.push_back(run.steps);
      const double e = run.relative_energy_error.value_or(std::nan(""));
      energy_errors.push_back(e);
      if (e > 0) ++positive;
      if (e < 0) ++negative;
      phase_errors.push_back(run.phase_error.value_or(std::nan("")));
    }
    json entry;
    entry["integrator"] = integrator.label;
    entry["scheme"] = description.scheme;
    entry["order"] = description.order.to_string();
    entry["nominal_exponent"] = description.order.value();
    entry["t2"] = description.t2;
    entry["symplectic"] = description.symplectic;
    entry["steps_from"] = integrator.steps_from;
    const auto energy_fit = fit_power_law(dts, energy_errors);
    entry["n_points"] = std::count_if(energy_errors.begin(), energy_errors.end(),
                                      [](double e) { return std::isfinite(e) && e != 0.0; });
    entry["exponent"] = energy_fit ? json(energy_fit->exponent) : json(nullptr);
    // The sign of the energy error at the smallest dt fitted (the largest step count).
    double sign = 1.0;
    for (std::size_t i = dts.size(); i-- > 0;)
      if (std::isfinite(energy_errors[i]) && energy_errors[i] != 0.0) {
        sign = energy_errors[i] < 0 ? -1.0 : 1.0;
        break;
      }
    entry["constant"] = energy_fit ? json(sign * energy_fit->constant) : json(nullptr);
    entry["constant_at_nominal_exponent"] = energy_fit ? json(sign * constant_at(description.order.value(), dts, energy_errors))
                                                       : json(nullptr);
    entry["energy_error_changes_sign"] = positive > 0 && negative > 0;
    // Where round-off shows: the smallest |error| fitted, and how many times the |error| at the smallest dt
    // exceeds the nominal power law through the largest dt, |e(dt_max)| (dt_min / dt_max)^order (about 1 in the
    // asymptotic range; round-off, which flattens the errors, makes it large). The runs are in increasing step
    // order: the first usable one has the largest |dt|, the last the smallest.
    std::optional<double> smallest, excess;
    std::vector<std::size_t> usable;
    for (std::size_t i = 0; i < dts.size(); ++i)
      if (std::isfinite(energy_errors[i]) && energy_errors[i] != 0.0) {
        smallest = std::min(smallest.value_or(INFINITY), std::abs(energy_errors[i]));
        usable.push_back(i);
      }
    if (usable.size() >= 2) {
      const std::size_t large = usable.front(), small = usable.back();
      excess = std::abs(energy_errors[small]) /
               (std::abs(energy_errors[large]) * std::pow(std::abs(dts[small] / dts[large]), description.order.value()));
    }
    entry["energy_error_smallest"] = optional_number(smallest);
    entry["energy_error_excess_at_smallest_dt"] = optional_number(excess);
    if (!dts.empty()) {
      const auto [dt_min, dt_max] = std::minmax_element(dts.begin(), dts.end(), [](double a, double b) {
        return std::abs(a) < std::abs(b);
      });
      entry["dt_min"] = *dt_min;
      entry["dt_max"] = *dt_max;
      entry["steps_min"] = *std::min_element(steps.begin(), steps.end());
      entry["steps_max"] = *std::max_element(steps.begin(), steps.end());
    } else {
      entry["dt_min"] = entry["dt_max"] = entry["steps_min"] = entry["steps_max"] = nullptr;
    }
    if (!study_.reference_q.empty()) {
      const auto phase_fit = fit_power_law(dts, phase_errors);
      entry["phase_exponent"] = phase_fit ? json(phase_fit->exponent) : json(nullptr);
      entry["phase_constant"] = phase_fit ? json(phase_fit->constant) : json(nullptr);
    }
    return entry;
  }

  std::size_t count_status(const std::string& status) const {
    std::size_t count = 0;
    for (const auto& list : runs_)
      for (const auto& run : list) count += run.status == status ? 1 : 0;
    return count;
  }

  std::string status() const {
    if (interrupted_) return "interrupted";
    if (!run_error_.empty() || count_status("failed") > 0) return "failed";
    if (count_status("diverged") > 0) return "diverged";
    return "completed";
  }

  ExitStatus exit_status() const {
    const auto s = status();
    if (s == "completed") return ExitStatus::success;
    if (s == "interrupted") return ExitStatus::interrupted;
    return ExitStatus::run_failed;
  }

  json summary(double wall_seconds) const {
    json summary;
    summary["status"] = status();
    if (!run_error_.empty()) summary["error"] = run_error_;
    summary["job"] = job_.file.string();
    summary["model"] = {{"plugin", loaded_.plugin.name()},
                        {"version", loaded_.plugin.version()},
                        {"path", loaded_.plugin.path().string()},
                        {"dimension", job_.initial.dimension},
                        {"parameters", json(loaded_.model.parameters())}};
    summary["hamiltonian"] = job_.integrator.form == HamiltonianForm::TTV ? "TTV" : "VVT";
    json study;
    study["t_end"] = job_.time.t_end;
    study["initial"] = {{"q", job_.initial.q}, {"p", job_.initial.p}};
    study["reference"] = study_.reference_q.empty()
                             ? json(nullptr)
                             : json{{"q", study_.reference_q}, {"p", study_.reference_p}};
    study["energy_initial"] = optional_number(energy_initial_);
    study["energy_available"] = energy_available_;
    study["runs"] = {{"completed", count_status("completed")},
                     {"diverged", count_status("diverged")},
                     {"failed", count_status("failed")},
                     {"interrupted", count_status("interrupted")}};
    summary["study"] = std::move(study);
    json fits = json::array();
    json failures = json::array();
    for (std::size_t i = 0; i < runs_.size(); ++i) {
      fits.push_back(fit_entry(study_.integrators[i], runs_[i]));
      for (const auto& run : runs_[i])
        if (run.status == "diverged" || run.status == "failed")
          failures.push_back({{"integrator", study_.integrators[i].label},
                              {"steps", run.steps},
                              {"status", run.status},
                              {"error", run.error}});
    }
    summary["fits"] = std::move(fits);
    if (!failures.empty()) summary["failures"] = std::move(failures);
    summary["output"] = {{"directory", options_.output_directory.string()}, {"convergence", "convergence.csv"}};
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
  std::vector<std::vector<StudyRun>> runs_;  // per integrator, in step order
  bool interrupted_ = false;
  std::string run_error_;
};

}  // namespace

RunOutcome run_study(const LoadedJob& job, const RunOptions& options) {
  return StudyExecution(job, options).execute();
}

}  // namespace nonsep::host
