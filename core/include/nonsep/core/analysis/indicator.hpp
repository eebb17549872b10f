#pragma once
// The seam for chaos indicators: what an indicator needs from a run, how it keeps its state, what it reports.
//
// The tangent machinery is shared: k tangent vectors per trajectory follow the exact tangent map of the run's
// integrator, LyapunovExponents re-orthonormalises them every m steps and keeps one LyapunovRecord per trajectory
// (lyapunov_exponents.hpp). An indicator is a small stateless object (its settings only) that says what it needs of
// that machinery (IndicatorNeeds) and turns it into its numbers; every trajectory's own state is state_size numbers
// that the caller owns, hands to the indicator at each step, and stores in checkpoints as numbers (restoring them bit
// for bit continues a run bit for bit). Its columns go to trajectories.csv and the series file, in order.
//
// The calls, for each trajectory (the caller's loop; the host's driver is one, run/tangent_block.hpp):
//   start(state)                     time 0, before the first step;
//   after_step(state, growth, dt)    after each step of dt, for an indicator that needs().first_growth, with
//                                    growth = ln(|v_1(t_k)| / |v_1(t_{k-1})|), the first vector's log-growth over
//                                    the step;
//   across_flow(state, a, at_start) for an indicator that needs().across_flow: once at time 0 (after start, with
//                                    at_start) and after each step (after after_step), with a = ln(|w_perp| / |w|)
//                                    of the first vector w, w_perp its component orthogonal to the flow direction
//                                    J grad H at the state (Euclidean, over (dq, dp)); a is NaN where grad H fails;
//   after_orthonormalization(state, r, k)  at each re-orthonormalisation of the run's k vectors (k at least what the
//                                    indicator needs), with its triangular factor R (k x k, row-major:
//                                    orthonormalize_state; needs().orthonormalization_factors);
//   values(state, lyapunov, out)     its columns' values now (out.size() == columns().size()).
//
// An indicator can instead need samples of the state (needs().samples.every > 0; frequency map analysis is one): the
// signals z = q_k + i p_k of the degrees of freedom needs().samples.degrees at every every-th step. The caller keeps
// them (the host's sample store, observers/sampled_indicator.hpp: in needs().samples.file, checkpointed there) and
// calls, once a trajectory has all of them (or retires early with at least needs().samples.minimum),
//   from_samples(signals, tau)       its columns' values and its spectra from one span per signal, tau = every dt;
// such an indicator follows no tangent vector and keeps no state_size numbers.
// The list of the indicators a job file can ask for is host/src/job/indicators.cpp.
#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/analysis/frequency_analysis.hpp"
#include "nonsep/core/analysis/lyapunov_record.hpp"

namespace nonsep {

// Samples of the state an indicator needs (none when every == 0).
struct SampleNeeds {
  std::uint64_t every = 0;           // steps between samples: steps every, 2 every, ..., N every
  std::vector<std::size_t> degrees;  // the signals q_k + i p_k, in column order
  std::uint64_t minimum = 0;         // the fewest samples it can analyse
  std::string file;                  // the output file that keeps them (a NumPy array)
  std::string spectra_file;          // its spectra's CSV file, "" for none
};

// What an indicator computes from a trajectory's samples: its columns' values (none: it could not, e.g. a sample
// that is not finite) and, per signal, the strongest terms for its spectra file (none without one).
struct SampleAnalysis {
  std::vector<double> values;
  std::vector<std::vector<FrequencyTerm>> spectra;
};

struct IndicatorNeeds {
  std::size_t tangent_vectors = 0;          // the first k vectors of the shared ones (the run follows the most asked)
  bool first_growth = false;                // the first vector's log-growth at every step
  bool orthonormalization_factors = false;  // the triangular factor of every re-orthonormalisation
  bool across_flow = false;                 // the first vector's share across the flow at time 0 and every step
                                            // (one gradient of H per state and step: the model needs grad H)
  std::size_t state_size = 0;               // numbers per trajectory
  SampleNeeds samples{};                    // samples of the state instead of tangent vectors
};

class Indicator {
 public:
  virtual ~Indicator() = default;

  // Its key under /analysis in job files, in summary.json and in checkpoints: "megno", "fli", ...
  virtual std::string name() const = 0;
  virtual IndicatorNeeds needs() const = 0;
  // Its columns in trajectories.csv and the series, in order.
  virtual std::vector<std::string> columns() const = 0;
  // What the columns hold, for summary.json ("trajectories.csv megno (Y), ...").
  virtual std::string description() const = 0;
  // Its settings as named integers, for summary.json (e.g. {"vectors", 3}); none by default.
  virtual std::vector<std::pair<std::string, std::size_t>> settings() const { return {}; }

  virtual void start(std::span<double> /*state*/) const {}
  virtual void after_step(std::span<double> /*state*/, double /*growth*/, double /*dt*/) const {}
  virtual void across_flow(std::span<double> /*state*/, double /*a*/, bool /*at_start*/) const {}
  virtual void after_orthonormalization(std::span<double> /*state*/, std::span<const double> /*r*/,
                                        std::size_t /*k*/) const {}
  virtual void values(std::span<const double> /*state*/, const LyapunovRecord& /*lyapunov*/,
                      std::span<double> /*out*/) const {}

  // For an indicator that needs samples: its analysis of `signals` (one span per needs().samples.degrees entry, all
  // of one length, at least needs().samples.minimum), sampled every `tau`; and the same indicator sampling every
  // `every` steps instead (scheme auto's step divides the job's: the same sampling times).
  virtual SampleAnalysis from_samples(std::span<const std::span<const std::complex<double>>> /*signals*/,
                                      double /*tau*/) const {
    return {};
  }
  virtual std::shared_ptr<const Indicator> sampling_every(std::uint64_t /*every*/) const { return nullptr; }
};

// Whether it follows tangent vectors (the tangent map's indicators) or needs samples of the state.
inline bool needs_samples(const Indicator& indicator) { return indicator.needs().samples.every > 0; }

// The indicators of a run, in the order of their columns.
using IndicatorList = std::vector<std::shared_ptr<const Indicator>>;

// Finite-time Lyapunov exponents lambda_0 .. lambda_(k-1) at the last orthonormalisation (LyapunovRecord::exponent),
// columns lyapunov0 .. lyapunov<k-1>; no state of its own.
class LyapunovIndicator final : public Indicator {
 public:
  explicit LyapunovIndicator(std::size_t k) : k_(k) {}
  std::string name() const override { return "lyapunov"; }
  IndicatorNeeds needs() const override { return {.tangent_vectors = k_}; }
  std::vector<std::string> columns() const override {
    std::vector<std::string> names;
    for (std::size_t j = 0; j < k_; ++j) names.push_back("lyapunov" + std::to_string(j));
    return names;
  }
  std::string description() const override { return "trajectories.csv lyapunov0 .. lyapunov" + std::to_string(k_ - 1); }
  void values(std::span<const double>, const LyapunovRecord& lyapunov, std::span<double> out) const override {
    for (std::size_t j = 0; j < k_; ++j) out[j] = lyapunov.exponent(j);
  }

 private:
  std::size_t k_;
};

}  // namespace nonsep
