#pragma once
// The results of the run's chaos indicators (nonsep/core/analysis/indicator.hpp: those of the job's list,
// job/indicators.cpp, that follow tangent vectors, Analysis::tangent_indicators), which the ensemble driver computes
// with the tangent vectors it follows (run/tangent_block.hpp, EnsembleSetup::indicators):
//   trajectories.csv  each indicator's columns, in the list's order: lyapunov0 .. lyapunov<k-1> (Benettin's
//                     finite-time exponents at the last re-orthonormalisation), megno, mean_megno (Y and <Y> of the
//                     first tangent vector: <Y> -> 2 on a quasi-periodic orbit, ~ lambda t / 2 on a chaotic one, 0 on
//                     a stable periodic one), sali and gali2 .. gali<k> (at the last re-orthonormalisation,
//                     nonsep/core/analysis/alignment_indices.hpp), fli, ofli, each when asked for; empty for a
//                     trajectory that diverged or failed.
//   lyapunov.csv      with /analysis/lyapunov/every = s > 0, the running values every s-th step:
//                     trajectory,step,t, then the same columns, in (step, trajectory) order.
// Checkpoints: lyapunov.csv's size and content hash, like trajectory.csv; the indicators' states are the driver's.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

class IndicatorColumns : public Observer, public CheckpointedObserver, public TrajectoryColumns {
 public:
  static constexpr const char* file_name = "lyapunov.csv";

  // The columns of `indicators`; the series every `every` steps (0: no lyapunov.csv). `records` (the driver's) must
  // outlive the observer. Creates the series file unless `resuming` (then restore() opens it). Throws OutputError.
  IndicatorColumns(const std::filesystem::path& path, const IndicatorList& indicators, std::uint64_t every,
                   const std::vector<TrajectoryRecord>& records, bool resuming);

  std::uint64_t next_event(std::uint64_t step) const override;
  void on_event(const Event& event) override;
  void on_end() override {
    if (file_) file_->flush();
  }

  std::string name() const override { return every_ > 0 ? "lyapunov_csv" : ""; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  void columns(std::vector<std::string>& names) const override;
  void cells(std::size_t trajectory, std::string& row) const override;

 private:
  // The cells of columns() after a row's first cells (lyapunov.csv: trajectory,step,t): a comma and a value each
  // (all empty when `values` is).
  void append_values(std::string& row, std::span<const double> values) const;

  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::uint64_t every_;
  const std::vector<TrajectoryRecord>& records_;
  std::optional<CsvAppender> file_;
};

}  // namespace nonsep::host
