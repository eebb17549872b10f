#pragma once
// The run's progress (progress_bar.hpp: a bar on a terminal, plain lines in a file) as an observer: updated after
// chunks, with the step, the active trajectories and the largest relative energy error so far.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/progress_bar.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

class EnsembleDriver;

class ProgressObserver : public Observer, public ChunkObserver {
 public:
  // `driver` outlives the observer; `energy` may be null; label and schedule as for ProgressBar.
  ProgressObserver(ProgressStyle style, double interval_seconds, const EnsembleDriver& driver,
                   const EnergyErrorObserver* energy, std::string label = {},
                   std::shared_ptr<ProgressSchedule> schedule = nullptr);

  // The stepping starts (at the resumed step after a resume): the time left is estimated from the steps after it.
  void prepare_blocks(std::size_t blocks) override;
  void after_chunk(std::uint64_t step) override;
  void before_finish(std::uint64_t, bool) override { bar_.finish(); }

 private:
  bool enabled_;
  ProgressBar bar_;
  const EnsembleDriver& driver_;
  const EnergyErrorObserver* energy_;
};

}  // namespace nonsep::host
