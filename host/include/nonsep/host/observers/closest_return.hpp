#pragma once
// /analysis/closest_return_after: from that time on, the smallest Euclidean phase-space distance
// |(q, p) - (q0, p0)| of each trajectory to its initial state, checked at every step, and where it was.
// trajectories.csv: closest_return_distance, closest_return_t, closest_return_step (empty when none).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

class ClosestReturnObserver : public Observer,
                              public ChunkObserver,
                              public StepObserver,
                              public CheckpointedObserver,
                              public TrajectoryColumns {
 public:
  struct Closest {
    std::optional<double> distance;
    std::uint64_t step = 0;
    double t = 0.0;
  };

  // `after`: the time from which returns count (|t| >= |after|); q0, p0: the initial states, state-major.
  ClosestReturnObserver(double after, std::size_t dimension, std::span<const double> q0, std::span<const double> p0);

  void prepare_blocks(std::size_t blocks) override { saved_.resize(blocks); }
  void on_step(std::uint64_t step, double t, const BlockView& block) override;
  void save_block(const BlockView& block) override;
  void restore_block(const BlockView& block) override;

  std::string name() const override { return "closest_return"; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override;
  void cells(std::size_t trajectory, std::string& row) const override;

  const Closest& closest(std::size_t trajectory) const { return closest_[trajectory]; }

 private:
  double after_;
  std::size_t dimension_;
  std::span<const double> q0_, p0_;
  std::vector<Closest> closest_;             // per trajectory
  std::vector<std::vector<Closest>> saved_;  // per block: its trajectories' values at the chunk's start
};

}  // namespace nonsep::host
