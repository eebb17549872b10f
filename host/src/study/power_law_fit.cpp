// The fits of a convergence study (convergence_study.hpp): a power law through each integrator's largest energy errors
// over the run and its phase errors at t_end, and the fit as summary.json's "fits" entry.
#include <algorithm>
#include <cmath>

#include "nonsep/host/study/convergence_study.hpp"

namespace nonsep::host {

using nlohmann::ordered_json;

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

template <class T>
ordered_json or_null(const std::optional<T>& value) {
  return value ? ordered_json(*value) : ordered_json(nullptr);
}

bool usable_error(double e) { return std::isfinite(e) && e != 0.0; }

// The first place where |error| grows as dt shrinks (errors in order of decreasing |dt|), over the usable ones at
// or above `floor` (below it round-off, not the method, moves them).
std::optional<NonMonotoneStep> first_rise(const std::vector<std::uint64_t>& steps, const std::vector<double>& error,
                                          double floor) {
  std::optional<std::size_t> previous;
  for (std::size_t i = 0; i < error.size(); ++i) {
    if (!usable_error(error[i]) || std::abs(error[i]) < floor) continue;
    if (previous && std::abs(error[i]) > std::abs(error[*previous]))
      return NonMonotoneStep{steps[*previous], std::abs(error[*previous]), steps[i], std::abs(error[i])};
    previous = i;
  }
  return std::nullopt;
}

ordered_json to_json(const std::optional<NonMonotoneStep>& rise) {
  if (!rise) return nullptr;
  return {{"steps", rise->steps_coarse},
          {"error", rise->error_coarse},
          {"steps_finer", rise->steps_fine},
          {"error_finer", rise->error_fine}};
}

}  // namespace

std::size_t round_off_floor_start(std::span<const double> dt, std::span<const double> error, double order) {
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < dt.size() && i < error.size(); ++i)
    if (usable_error(error[i])) usable.push_back(i);
  const auto slope_below_half = [&](std::size_t a, std::size_t b) {
    const double slope = std::log(std::abs(error[a] / error[b])) / std::log(std::abs(dt[a] / dt[b]));
    return !(slope >= order / 2);
  };
  for (std::size_t k = 0; k < usable.size(); ++k) {
    const double e = std::abs(error[usable[k]]);
    if (e < round_off_energy_error) return usable[k];
    if (e < round_off_at_most && ((k > 0 && slope_below_half(usable[k - 1], usable[k])) ||
                                  (k + 1 < usable.size() && slope_below_half(usable[k], usable[k + 1]))))
      return usable[k];
  }
  return dt.size();
}

StudyFit fit_study(const StudyIntegrator& integrator, const IntegratorDescription& description,
                   const std::vector<StudyRun>& runs, bool with_reference, double phase_scale) {
  std::vector<double> all_dts, all_energy_errors;
  for (const auto& run : runs)
    if (run.status == TrajectoryStatus::completed) {
      all_dts.push_back(run.dt);
      all_energy_errors.push_back(run.max_abs_relative_energy_error.value_or(std::nan("")));
    }
  const std::size_t floor = round_off_floor_start(all_dts, all_energy_errors, description.order.value());
  StudyFit fit;
  std::vector<double> dts, energy_errors, end_energy_errors, phase_errors;
  std::vector<std::uint64_t> steps;
  int positive = 0, negative = 0;
  std::size_t completed = 0;
  for (const auto& run : runs) {
    if (run.status != TrajectoryStatus::completed) continue;
    if (completed++ >= floor) {
      ++fit.points_at_round_off;
      fit.round_off_dt_max = fit.round_off_dt_max.value_or(run.dt);
      const double e = run.max_abs_relative_energy_error.value_or(INFINITY);
      fit.round_off_error_smallest = std::min(fit.round_off_error_smallest.value_or(INFINITY), e);
      continue;
    }
    dts.push_back(run.dt);
    steps.push_back(run.steps);
    const double at_end = run.relative_energy_error.value_or(std::nan(""));
    end_energy_errors.push_back(at_end);
    if (at_end > 0) ++positive;
    if (at_end < 0) ++negative;
    energy_errors.push_back(run.max_abs_relative_energy_error.value_or(std::nan("")));
    phase_errors.push_back(run.phase_error.value_or(std::nan("")));
  }
  fit.integrator = integrator.label;
  fit.description = description;
  fit.steps_from = integrator.steps_from;
  fit.points = static_cast<std::size_t>(
      std::count_if(energy_errors.begin(), energy_errors.end(), [](double e) { return std::isfinite(e) && e != 0.0; }));
  // The sign of the energy error at t_end at the smallest dt fitted (the largest step count).
  double sign = 1.0;
  for (std::size_t i = dts.size(); i-- > 0;)
    if (usable_error(energy_errors[i]) && usable_error(end_energy_errors[i])) {
      sign = end_energy_errors[i] < 0 ? -1.0 : 1.0;
      break;
    }
  if (const auto energy_fit = fit_power_law(dts, energy_errors)) {
    fit.exponent = energy_fit->exponent;
    fit.constant = sign * energy_fit->constant;
    fit.constant_at_nominal_exponent = sign * constant_at(description.order.value(), dts, energy_errors);
  }
  fit.energy_error_changes_sign = positive > 0 && negative > 0;
  // The runs are in increasing step order: the first usable one has the largest |dt|, the last the smallest.
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < dts.size(); ++i)
    if (std::isfinite(energy_errors[i]) && energy_errors[i] != 0.0) {
      fit.energy_error_smallest = std::min(fit.energy_error_smallest.value_or(INFINITY), std::abs(energy_errors[i]));
      usable.push_back(i);
    }
  if (usable.size() >= 2) {
    const std::size_t large = usable.front(), small = usable.back();
    fit.energy_error_excess_at_smallest_dt =
        std::abs(energy_errors[small]) /
        (std::abs(energy_errors[large]) * std::pow(std::abs(dts[small] / dts[large]), description.order.value()));
  }
  if (!dts.empty()) {
    const auto [dt_min, dt_max] =
        std::minmax_element(dts.begin(), dts.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
    fit.dt_min = *dt_min;
    fit.dt_max = *dt_max;
    fit.steps_min = *std::min_element(steps.begin(), steps.end());
    fit.steps_max = *std::max_element(steps.begin(), steps.end());
  }
  fit.energy_error_rises = first_rise(steps, energy_errors, round_off_energy_error);
  fit.with_reference = with_reference;
  // Phase errors have the scale of the state: below 1e-12 of it they are round-off too.
  if (with_reference) fit.phase_error_rises = first_rise(steps, phase_errors, 1e-12 * phase_scale);
  if (with_reference)
    if (const auto phase_fit = fit_power_law(dts, phase_errors)) {
      fit.phase_exponent = phase_fit->exponent;
      fit.phase_constant = phase_fit->constant;
    }
  return fit;
}

ordered_json to_json(const StudyFit& fit) {
  ordered_json entry;
  entry["integrator"] = fit.integrator;
  entry["scheme"] = fit.description.scheme;
  entry["order"] = fit.description.order.to_string();
  entry["nominal_exponent"] = fit.description.order.value();
  entry["t2"] = fit.description.t2;
  entry["symplectic"] = fit.description.symplectic;
  entry["steps_from"] = fit.steps_from;
  entry["n_points"] = fit.points;
  entry["exponent"] = or_null(fit.exponent);
  entry["constant"] = or_null(fit.constant);
  entry["constant_at_nominal_exponent"] = or_null(fit.constant_at_nominal_exponent);
  entry["energy_error_changes_sign"] = fit.energy_error_changes_sign;
  entry["energy_error_smallest"] = or_null(fit.energy_error_smallest);
  entry["energy_error_excess_at_smallest_dt"] = or_null(fit.energy_error_excess_at_smallest_dt);
  entry["n_points_at_round_off"] = fit.points_at_round_off;
  entry["round_off_dt_max"] = or_null(fit.round_off_dt_max);
  entry["energy_error_rises"] = to_json(fit.energy_error_rises);
  if (fit.dt_min) {
    entry["dt_min"] = *fit.dt_min;
    entry["dt_max"] = or_null(fit.dt_max);
    entry["steps_min"] = or_null(fit.steps_min);
    entry["steps_max"] = or_null(fit.steps_max);
  } else {
    // Without a completed run these four are null, in the order summary.json has always had them in that case.
    for (const char* key : {"steps_max", "steps_min", "dt_max", "dt_min"}) entry[key] = nullptr;
  }
  if (fit.with_reference) {
    entry["phase_exponent"] = or_null(fit.phase_exponent);
    entry["phase_constant"] = or_null(fit.phase_constant);
    entry["phase_error_rises"] = to_json(fit.phase_error_rises);
  }
  return entry;
}

}  // namespace nonsep::host
