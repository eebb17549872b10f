#pragma once
// The relative energy error |H - H0| / |H0| of every trajectory, over the steps where H is evaluated: step 0, every
// written sample (output.every), every output.energy_every-th step, the last step, and the final state of every
// trajectory (where it stopped early: its last state before a divergence, at its last Poincare crossing, ...; the
// driver evaluates H there and on_retire takes it into the maximum). Optionally bounded
// (analysis.max_relative_energy_error): a trajectory whose error exceeds the bound there retires as "inaccurate".
// trajectories.csv: max_abs_relative_energy_error (empty when H0 is unknown or 0).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

// The trajectory with the largest error so far.
struct LargestEnergyError {
  double value = 0.0;
  std::size_t trajectory = 0;
};

class EnergyErrorObserver : public Observer, public CheckpointedObserver, public TrajectoryColumns {
 public:
  // energy_every: output.energy_every (0: none of its own); bound: analysis.max_relative_energy_error.
  EnergyErrorObserver(std::size_t trajectories, std::uint64_t energy_every, std::optional<double> bound);

  std::uint64_t next_event(std::uint64_t step) const override;
  bool needs_energy(std::uint64_t step) const override { return energy_every_ > 0 && step % energy_every_ == 0; }
  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;

  std::string name() const override { return "energy_error"; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override;
  void cells(std::size_t trajectory, std::string& row) const override;

  // The largest |dH/H0| of a trajectory (nothing while unknown).
  std::optional<double> max_abs(std::size_t trajectory) const { return max_abs_[trajectory]; }
  // Over the ensemble; nothing while no error is known.
  std::optional<LargestEnergyError> largest() const;
  // Whether H was evaluated at a step after step 0 (before that, every error known is step 0's: 0).
  bool evaluated_after_start() const { return evaluated_after_start_; }

 private:
  std::uint64_t energy_every_;
  std::optional<double> bound_;
  std::vector<std::optional<double>> max_abs_;
  bool evaluated_after_start_ = false;

  // Takes (H - H0) / H0 of `trajectory` into its maximum and returns it (nothing when unknown).
  std::optional<double> include(std::size_t trajectory, std::optional<double> energy,
                                std::optional<double> energy_initial);
};

}  // namespace nonsep::host
