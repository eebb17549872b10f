#pragma once
// poincare.csv: the crossings of every trajectory with a surface of section s(q, p) = normal . (q, p) - value = 0
// (/analysis/poincare), streamed as the run goes. Header
//   trajectory,crossing,step,t,q0,...,q<n-1>,p0,...,p<n-1>,H
// `crossing` counts a trajectory's crossings from 0; `step` is the step within which it crossed (the crossing lies
// between t_(step-1) and t_step). Rows are in (step, trajectory) order, the same for any number of threads.
//
// How a crossing is found: an every-step observer. It keeps each trajectory's state before the step (taken from
// the block at the start of every chunk, then from each step it sees) and, when s changes sign over a step in the
// asked direction ("+": from s < 0 to s >= 0, "-": from s > 0 to s <= 0, "both"), hands the state before the step
// to nonsep::PoincareCrossingLocator (nonsep/core/analysis/poincare_crossing.hpp) with the run's own integrator, on the
// worker thread's plugin instance: a fractional step tau of that integrator from the state before, with TOMS 748 on
// s(tau). The row is the evaluated point with the smallest |s|: on the numerical trajectory, with |s| at round-off
// (<= 1e-12 (|normal| |(q, p)| + |value|) in the tests). H is that point's energy (empty when the plugin has no
// Hessians). The stepping of the run itself is not changed.
//
// max_crossings: a trajectory that reaches it stops at that step, status "completed" with the message
// "stopped at its Nth Poincare crossing (max_crossings)" (1st, 2nd, ...); its final state is the state at that step.
// When the plugin fails while a crossing is located, the trajectory stops at that step as "failed", with the plugin's
// message.
//
// Checkpoints: the file's size and content hash (like trajectory.csv) and each trajectory's crossing count.
// trajectories.csv gets a column poincare_crossings.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/analysis/poincare_crossing.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

class PoincareSectionObserver : public Observer,
                                public ChunkObserver,
                                public StepObserver,
                                public CheckpointedObserver,
                                public TrajectoryColumns {
 public:
  static constexpr const char* file_name = "poincare.csv";

  // `time` must outlive the observer. `energy`: whether H can be evaluated (the plugin has Hessians). Creates the
  // file, or, when `resuming`, leaves it to restore(). Throws OutputError.
  PoincareSectionObserver(const std::filesystem::path& path, const PoincareSection& section,
                          const IntegratorSpec& integrator, const TimeGrid& time, std::size_t dimension,
                          std::size_t trajectories, bool energy, bool resuming);

  void prepare_blocks(std::size_t blocks) override;
  void on_step(std::uint64_t step, double t, const BlockView& block) override;
  void save_block(const BlockView& block) override;
  void restore_block(const BlockView& block) override;
  void after_chunk(std::uint64_t step) override;
  void on_end() override { file_->flush(); }

  std::string name() const override { return "poincare_csv"; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override { names.push_back("poincare_crossings"); }
  void cells(std::size_t trajectory, std::string& row) const override;

  std::uint64_t total_crossings() const;

 private:
  struct Found {
    std::uint64_t step = 0;
    std::size_t trajectory = 0;
    std::uint64_t crossing = 0;
    double t = 0.0;
    std::vector<double> q, p;
    std::optional<double> energy;
  };
  // What one block's worker thread owns.
  struct BlockState {
    PoincareCrossingLocator<Integrator> locator;
    EnergyEvaluator energy;
    SectionCrossing crossing;
    std::vector<Found> found;  // in the current chunk, in step order
    std::vector<std::uint64_t> counts_at_chunk_start;
  };

  bool crosses(double before, double after) const;
  void remember(const BlockView& block);
  void write(const Found& found);

  SectionPlane plane_;
  CrossingDirection direction_;
  std::optional<std::uint64_t> max_crossings_;
  IntegratorSpec integrator_;
  const TimeGrid& time_;
  std::size_t dimension_;
  bool energy_;
  std::filesystem::path path_;
  std::optional<CsvAppender> file_;
  std::vector<double> previous_q_, previous_p_;  // per trajectory: its state before the current step
  std::vector<std::uint64_t> counts_;            // per trajectory: crossings so far
  std::vector<BlockState> blocks_;
};

}  // namespace nonsep::host
