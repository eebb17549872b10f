#pragma once
// The run's progress (progress_bar.hpp: a bar on a terminal, plain lines in a file) as an observer: updated after
// chunks, with the step, the active trajectories and the largest relative energy error so far.
#include <memory>
#include <string>
#include <utility>

#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/progress_bar.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

class ProgressObserver : public Observer, public ChunkObserver {
 public:
  // `energy` may be null; label and schedule as for ProgressBar.
  ProgressObserver(ProgressStyle style, double interval_seconds, const EnsembleDriver& driver,
                   const EnergyErrorObserver* energy, std::string label = {},
                   std::shared_ptr<ProgressSchedule> schedule = nullptr)
      : enabled_(style != ProgressStyle::none),
        bar_(style, driver.time().steps, driver.time().t_end, interval_seconds, std::move(label), std::move(schedule)),
        driver_(driver),
        energy_(energy) {}

  void after_chunk(std::uint64_t step) override {
    if (!enabled_) return;
    std::optional<double> largest;
    if (energy_)
      if (const auto l = energy_->largest()) largest = l->value;
    bar_.update(step, driver_.time().time_at(step), driver_.active_count(), largest);
  }
  void before_finish(std::uint64_t, bool) override { bar_.finish(); }

 private:
  bool enabled_;
  ProgressBar bar_;
  const EnsembleDriver& driver_;
  const EnergyErrorObserver* energy_;
};

}  // namespace nonsep::host
