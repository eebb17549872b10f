#pragma once
// Orbits that run off with bounded energy: a trajectory whose scale, max(|q_i|, |p_i|), grew more than `growth`
// times beyond its reference scale while its relative energy error |dH/H0| stayed at most `small_error`. The
// reference scale is the largest seen in the first tenth of the run (|t| <= |t_end|/10, step 0 included): a bounded
// orbit has shown its extent by then, one on a non-compact shell has not.
// Such an orbit follows a non-compact energy shell (docs/method.md, "Non-compact energy shells"): the integrator
// keeps H, and H does not keep the orbit. Seen where H is evaluated (step 0, samples, output.energy_every, the last
// step) and in the final state of a retired trajectory; not checkpointed (a resumed run reports what it saw
// after resuming). What it finds goes into the run's messages (run_command), not into files.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nonsep/host/run/observer.hpp"

namespace nonsep::host {

// The furthest a trajectory got with a small energy error, once it got past the threshold.
struct Runaway {
  double reference_scale = 0.0, scale = 0.0;  // the reference scale, and max(|q_i|, |p_i|) there
  double t = 0.0;                             // where
  double largest_error = 0.0;                 // the largest |dH/H0| seen up to there
};

class RunawayObserver : public Observer {
 public:
  static constexpr double growth = 3.0, small_error = 1e-2;

  // The initial states, `count` of dimension n (q and p in the job's layout), and the run's end time.
  RunawayObserver(std::span<const double> q, std::span<const double> p, std::size_t count, std::size_t n, double t_end);

  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;

  // Per trajectory, in job order; nothing for those that did not run off.
  const std::vector<std::optional<Runaway>>& runaways() const { return runaways_; }

 private:
  double reference_until_;
  std::vector<double> reference_scale_, largest_error_;
  std::vector<std::optional<Runaway>> runaways_;

  void see(std::size_t trajectory, double t, std::span<const double> q, std::span<const double> p,
           std::optional<double> energy, std::optional<double> energy_initial);
};

// The sentence for one runaway: "|q| or |p| grew from 0.5 to 31 by t = 40 while |dH/H0| stayed at most 2e-06: the
// energy shell may be non-compact ...".
std::string runaway_text(const Runaway& runaway);

}  // namespace nonsep::host
