#pragma once
// Convergence studies: a job with /study (README.md, "Convergence studies") runs its model from its one
// initial state to time.t_end once per integrator and step count, and measures at t_end
//   - the relative energy error (H - H0) / H0 (needs the plugin's Hessians; empty otherwise), and
//   - the phase-space error |(q, p) - (q_ref, p_ref)| (Euclidean) against /study/reference, when given.
// Outputs, in the output folder:
//   convergence.csv  one row per run, header
//     integrator,scheme,order,t2,symplectic,dt,steps,basic_steps,grad_T,grad_V,relative_energy_error,phase_error,status
//     (numbers shortest round-trip; errors empty when unknown; status completed, diverged or failed)
//   summary.json     the study, and under "fits" one entry per integrator: the least-squares line through
//     (log dt, log |relative energy error|) over the completed runs, as error = constant * dt^exponent, where the
//     constant's sign is that of the energy error at the smallest dt (also the constant with the exponent fixed
//     at the nominal order); the same for the phase error when a
//     reference is given; the range of dt and steps fitted and whether the energy error changed sign in it.
#include <cstddef>
#include <optional>
#include <span>

#include "nonsep/host/job.hpp"
#include "nonsep/host/run/run_job.hpp"

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

// Runs the study of `job` (job.job.study must be set). Throws OutputError, before anything is computed, when the
// output folder or convergence.csv cannot be created. A run that diverges or that the plugin fails on is a row
// with that status, left out of the fits, and makes the exit status run_failed; SIGINT (options.stop_requested)
// stops after the current step with status "interrupted". summary.json is written in every case.
RunOutcome run_study(const LoadedJob& job, const RunOptions& options);

}  // namespace nonsep::host
