#include "nonsep/host/observers/progress.hpp"

#include <cmath>
#include <optional>
#include <utility>

#include "nonsep/host/run/ensemble_driver.hpp"

namespace nonsep::host {

ProgressObserver::ProgressObserver(ProgressStyle style, double interval_seconds, const EnsembleDriver& driver,
                                   const EnergyErrorObserver* energy, std::string label,
                                   std::shared_ptr<ProgressSchedule> schedule)
    : enabled_(style != ProgressStyle::none),
      bar_(style, driver.time().steps, driver.time().t_end, interval_seconds, std::move(label), std::move(schedule)),
      driver_(driver),
      energy_(energy) {}

void ProgressObserver::prepare_blocks(std::size_t) { bar_.start_from(driver_.steps_completed()); }

void ProgressObserver::after_chunk(std::uint64_t step) {
  if (!enabled_) return;
  // Nothing without H; "n/a" while H was evaluated at step 0 only (the largest error there is 0 by definition).
  std::optional<double> largest;
  if (const auto known = energy_ ? energy_->largest() : std::nullopt)
    largest = energy_->evaluated_after_start() ? known->value : std::nan("");
  bar_.update(step, driver_.time().time_at(step), driver_.active_count(), largest);
}

}  // namespace nonsep::host
