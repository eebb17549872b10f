#pragma once
// /analysis/error_estimate: the global error of every trajectory estimated by step halving. The run's trajectories
// are integrated a second time with half the step (the same scheme, 2N steps of dt/2: FineRun, which launch/ runs
// before the run itself); at each comparison step k of the run (its samples, output.every, or 100 evenly spaced
// steps without samples; and the last step) Richardson extrapolation with the scheme's order p gives
//   estimated_phase_error            |(q, p)_dt(t_k) - (q, p)_dt/2(t_k)| / (1 - 2^-p)
//   estimated_relative_energy_error  (H_dt(t_k) - H_dt/2(t_k)) / H0 / (1 - 2^-p)   (needs the plugin's Hessians)
// the error of the run's own state against the exact flow, when both runs are in the asymptotic range of the
// scheme. The energy error itself, (H - H0)/H0, is known exactly at the samples (trajectory.csv); its estimate is a
// check of that assumption: the two agree where the estimate holds.
//
// Horizon. The difference of the two runs is a small error term only while it stays small against the state: once
// estimated_phase_error exceeds error_estimate_separation (0.1) times max(|(q, p)(t_k)|, |(q, p)(0)|), the runs
// have separated (on a chaotic orbit the difference grows exponentially until it is as large as the orbit) and no
// estimate after that time holds; the trajectory's error_estimate_horizon is the time of the first such comparison.
//
// Outputs: error_estimate.csv, one row per trajectory and comparison step, in (step, trajectory) order:
//   trajectory,step,t,estimated_phase_error,estimated_relative_energy_error,separated
// trajectories.csv columns: estimated_phase_error, estimated_relative_energy_error (at the trajectory's last
// comparison: t_end for a completed one), error_estimate_t (that time), error_estimate_horizon (empty while the runs
// have not separated) and error_estimate ("within_horizon", "separated", or "unavailable" when the finer run stopped
// before that step: it diverged or the plugin failed on it, its message in summary.json). Memory: the finer run's
// states at the comparison steps, count x points x (2n + 2) doubles. Checkpoints: the per-trajectory values and
// error_estimate.csv's size and content hash; the finer run is computed again on resume (it is deterministic).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

inline constexpr double error_estimate_separation = 0.1;
inline constexpr std::uint64_t error_estimate_points = 100;  // comparisons without samples

// 1 / (1 - 2^-order): the coarse run's error over the difference of the runs at dt and dt/2.
double richardson_factor(double order);

// The comparison steps of a run of `steps` steps that writes samples every `every` steps (0: none), in order, the
// last one `steps`.
std::vector<std::uint64_t> error_estimate_steps(std::uint64_t steps, std::uint64_t every);

// The finer run's states at the comparison steps (its steps 2k): an observer of that run.
class FineRun : public Observer {
 public:
  FineRun(std::size_t trajectories, std::size_t dimension, std::vector<std::uint64_t> coarse_steps);

  std::uint64_t next_event(std::uint64_t step) const override;
  bool needs_energy(std::uint64_t step) const override { return index_of(step).has_value(); }
  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;

  const std::vector<std::uint64_t>& coarse_steps() const { return coarse_steps_; }
  std::size_t trajectories() const { return stopped_.size(); }
  // The finer run's q then p (2n numbers) of `trajectory` at comparison `point`; nothing when it had stopped before.
  std::optional<std::span<const double>> state(std::size_t trajectory, std::size_t point) const;
  double energy(std::size_t trajectory, std::size_t point) const;  // H there (NaN when unknown)
  double initial_length(std::size_t trajectory) const;             // |(q, p)(0)|
  // Why a trajectory of the finer run stopped early ("" when it did not).
  const std::string& stopped(std::size_t trajectory) const { return stopped_[trajectory]; }

 private:
  std::optional<std::size_t> index_of(std::uint64_t fine_step) const;

  std::size_t dimension_;
  std::vector<std::uint64_t> coarse_steps_;
  std::vector<double> states_;           // [trajectory][point][2n + 2]: q, p, H, |(q, p)(0)|
  std::vector<unsigned char> recorded_;  // [trajectory][point]
  std::vector<std::string> stopped_;
};

class ErrorEstimateObserver : public Observer, public CheckpointedObserver, public TrajectoryColumns {
 public:
  static constexpr const char* file_name = "error_estimate.csv";
  // `fine`: the finer run, complete. `order`: the scheme's. `times`: t at the run's steps (TimeGrid::time_at).
  // Creates error_estimate.csv unless `resuming` (then restore() opens it). Throws OutputError.
  ErrorEstimateObserver(const std::filesystem::path& path, FineRun fine, double order, std::size_t dimension,
                        bool resuming);

  std::uint64_t next_event(std::uint64_t step) const override;
  bool needs_energy(std::uint64_t step) const override;
  void on_event(const Event& event) override;
  void on_end() override { file_->flush(); }

  std::string name() const override { return "error_estimate"; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override;
  void cells(std::size_t trajectory, std::string& row) const override;

  // Over the ensemble: the largest estimated phase error at the last comparison, how many trajectories separated,
  // how many had no estimate (the finer run stopped), and the finer run's messages (summary.json).
  struct Totals {
    std::optional<double> largest_phase_error, largest_energy_error;
    std::size_t separated = 0, unavailable = 0;
    std::optional<double> earliest_horizon;
  };
  Totals totals() const;
  const FineRun& fine() const { return fine_; }

 private:
  struct Estimate {
    std::optional<double> phase, energy;
    std::optional<double> t;        // of the last comparison
    std::optional<double> horizon;  // the first comparison at which the runs had separated
    bool unavailable = false;
  };

  std::filesystem::path path_;
  FineRun fine_;
  double factor_;
  std::size_t dimension_;
  std::vector<Estimate> estimates_;
  std::optional<CsvAppender> file_;
};

}  // namespace nonsep::host
