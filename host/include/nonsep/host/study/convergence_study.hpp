#pragma once
// Convergence studies: a job with /study (docs/studies.md) runs its model from its one
// initial state to time.t_end once per integrator and step count, and measures
//   - the relative energy error (H - H0) / H0 at t_end and the largest |(H - H0) / H0| over the run, H evaluated at
//     every step (needs the plugin's Hessians; empty otherwise), and
//   - the phase-space error |(q, p) - (q_ref, p_ref)| (Euclidean) at t_end against /study/reference, when given.
// Outputs, in the output folder:
//   convergence.csv  one row per run, header
//     integrator,scheme,order,t2,symplectic,dt,steps,basic_steps,grad_T,grad_V,relative_energy_error,phase_error,status,
//     family,grad_H,max_abs_relative_energy_error
//     (numbers shortest round-trip; errors empty when unknown; status completed, diverged or failed)
//   work_precision.csv  the same runs with their cost (docs/studies.md)
//   summary.json     the study, and under "fits" one entry per integrator: the least-squares line through
//     (log dt, log max |relative energy error|) over the completed runs, as error = constant * dt^exponent, where the
//     constant's sign is that of the energy error at t_end at the smallest dt (also the constant with the exponent
//     fixed at the nominal order); the same for the phase error when a reference is given; the range of dt and steps
//     fitted and whether the energy error changed sign in it.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/model.hpp"
#include "nonsep/core/schemes/integrator_description.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"

namespace nonsep::host {

// error ≈ constant * dt^exponent, fitted on log |error| against log |dt|.
struct PowerLawFit {
  double exponent = 0.0;
  double constant = 0.0;  // positive; the caller attaches a sign
  std::size_t points = 0;
};

// Least squares on the pairs with a finite, non-zero error and non-zero dt. Returns nothing with fewer than two
// such pairs or when all their dt are equal. `dt` and `error` have the same length.
std::optional<PowerLawFit> fit_power_law(std::span<const double> dt, std::span<const double> error);

// Round-off in a study's relative energy errors (double precision; H is a sum of products and its error
// accumulates over the steps): below round_off_energy_error an error is round-off alone; below round_off_at_most
// it is round-off where it falls more slowly than half the nominal order predicts.
inline constexpr double round_off_energy_error = 5e-14;
inline constexpr double round_off_at_most = 1e-8;

// Where the round-off floor starts in errors ordered by decreasing |dt| (a study's runs in increasing step order):
// the first usable error (finite, non-zero) below round_off_energy_error, or below round_off_at_most with a local
// slope d log|error| / d log|dt| under order / 2 from the previous usable one or to the next (it fell too little,
// or the next one does). That point and every later one are at the floor. Returns dt.size() when there is none.
std::size_t round_off_floor_start(std::span<const double> dt, std::span<const double> error, double order);

// One run of a study: one integrator at one step count.
struct StudyRun {
  std::uint64_t steps = 0;
  double dt = 0.0;
  TrajectoryStatus status = TrajectoryStatus::completed;  // completed, diverged, failed or interrupted
  std::string error;                                      // why it diverged or failed; "" otherwise
  std::uint64_t basic_steps = 0;
  EvaluationCounts evaluations;
  std::optional<double> relative_energy_error, phase_error;  // at t_end; completed runs only
  // The largest |dH/H0| over the run, H evaluated at every step (completed runs with Hessians only).
  std::optional<double> max_abs_relative_energy_error;
  double wall_seconds = 0.0;  // the median over the repeats (/study/repeats) of the driver's run
  int repeats = 0;            // how many runs the median is over
};

// Where a study's errors grow as dt shrinks (a ladder that is not monotone): the first pair of fitted runs, in step
// order, whose finer run has the larger |error|.
struct NonMonotoneStep {
  std::uint64_t steps_coarse = 0;
  double error_coarse = 0.0;
  std::uint64_t steps_fine = 0;
  double error_fine = 0.0;
};

// The fits of one integrator over its completed runs above the round-off floor (round_off_floor_start: those at
// it are left out and counted) (summary.json "fits"). Values that cannot be fitted (fewer than two usable points)
// are empty; the phase fit, over the same runs, exists only with /study/reference.
struct StudyFit {
  std::string integrator;             // the label
  IntegratorDescription description;  // scheme, order (the nominal exponent), t2, symplectic
  std::string steps_from;
  std::size_t points = 0;  // runs fitted: with a finite, non-zero energy error above the round-off floor
  // The completed runs left out at the round-off floor: how many, the largest |dt| among them and their smallest
  // |energy error|.
  std::size_t points_at_round_off = 0;
  std::optional<double> round_off_dt_max, round_off_error_smallest;
  std::optional<double> exponent, constant, constant_at_nominal_exponent;
  bool energy_error_changes_sign = false;
  // Where round-off shows: the smallest |energy error| fitted, and how many times the |error| at the smallest dt
  // exceeds the nominal power law through the largest dt (about 1 in the asymptotic range; round-off, which
  // flattens the errors, makes it large).
  std::optional<double> energy_error_smallest, energy_error_excess_at_smallest_dt;
  std::optional<double> dt_min, dt_max;  // by |dt|, over the runs fitted
  std::optional<std::uint64_t> steps_min, steps_max;
  // Where the largest |dH/H0| (the phase error) rises from one fitted run to the next finer one: the power law
  // does not describe such a ladder (pre-asymptotic errors, or errors that oscillate in dt); nothing when monotone.
  std::optional<NonMonotoneStep> energy_error_rises, phase_error_rises;
  bool with_reference = false;
  std::optional<double> phase_exponent, phase_constant;
};

// What a study ended with: its status, its runs per integrator (in the order of /study/integrators, each in step
// order) and their fits. summary.json is written from these.
struct StudyOutcome {
  ExitStatus exit_status = ExitStatus::success;           // success, run_failed or interrupted
  TrajectoryStatus status = TrajectoryStatus::completed;  // interrupted, failed, diverged or completed
  std::string error;  // why the study as a whole failed (the plugin, an output); "" otherwise
  StatusCounts run_counts;
  std::vector<StudyFit> fits;               // one per integrator
  std::vector<std::vector<StudyRun>> runs;  // per integrator, as fits
  nlohmann::ordered_json summary;           // what summary.json holds
};

// The fits of `runs`, the runs of `integrator` (described by `description`); `with_reference` adds the phase fit,
// `phase_scale` (|(q, p)_ref|, 1 when unknown) sets the round-off level of its phase errors.
StudyFit fit_study(const StudyIntegrator& integrator, const IntegratorDescription& description,
                   const std::vector<StudyRun>& runs, bool with_reference, double phase_scale = 1.0);
// fit as summary.json's "fits" entry.
nlohmann::ordered_json to_json(const StudyFit& fit);

// Runs the study of `job` (job.job.is_study() must hold). Throws OutputError, before anything is computed, when the
// output folder or convergence.csv cannot be created. A run that diverges or that the plugin fails on is a row
// with that status, left out of the fits, and makes the exit status run_failed; SIGINT (options.stop_requested)
// stops after the current step with status "interrupted". summary.json is written in every case.
StudyOutcome run_study(const LoadedJob& job, const RunOptions& options);

}  // namespace nonsep::host
