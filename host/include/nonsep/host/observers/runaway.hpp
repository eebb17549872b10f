#pragma once
// Orbits that run off with bounded energy: a trajectory whose scale, max(|q_i|, |p_i|), grew more than `growth`
// times beyond its reference scale (leaving out each q_i whose momentum p_i is still exactly its initial value: a
// cyclic coordinate such as the time or an angle, which grows while the orbit stays bounded) while its relative energy
// error |dH/H0| stayed at most `small_error`. The reference scale is the largest in the first tenth of the run (|t| <=
// |t_end|/10, step 0 included): a bounded orbit has shown its extent by then, one on a non-compact shell has not. Such
// an orbit follows a non-compact energy shell (docs/method.md, "Non-compact energy shells"): the integrator keeps H,
// and H does not keep the orbit. The scale is watched where the orbit is, not only where it is sampled: at every
// stride()-th step of the run (about `watched_steps` steps, evenly spaced, through the plugin's kernel, which the
// watching does not change), at the steps where H is evaluated and in the final state of a retired trajectory; |dH/H0|
// where H is evaluated (step 0, samples, output.energy_every, the last step, final states): the furthest point so far
// counts as a runaway where H is next evaluated, with the largest |dH/H0| up to there. Checkpointed, so that a resumed
// run finds what an uninterrupted one finds. What it finds goes into the run's messages (run_command), not into files.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "nonsep/host/run/observer.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

// The furthest a trajectory got with a small energy error, once it got past the threshold.
struct Runaway {
  double reference_scale = 0.0, scale = 0.0;  // the reference scale, and max(|q_i|, |p_i|) there
  double t = 0.0;                             // where
  double largest_error = 0.0;                 // the largest |dH/H0| seen up to there
};

class RunawayObserver : public Observer, public ChunkObserver, public StepObserver, public CheckpointedObserver {
 public:
  static constexpr double growth = 3.0, small_error = 1e-2;
  static constexpr std::uint64_t watched_steps = 1000;

  // The initial states, `count` of dimension n (q and p in the job's layout), and the run's time grid.
  RunawayObserver(std::span<const double> q, std::span<const double> p, std::size_t count, std::size_t n,
                  const TimeGrid& time);

  void on_event(const Event& event) override;
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override;

  void prepare_blocks(std::size_t blocks) override { saved_.resize(blocks); }
  std::uint64_t stride() const override { return stride_; }
  void on_step(std::uint64_t step, double t, const BlockView& block) override;
  void save_block(const BlockView& block) override;
  void restore_block(const BlockView& block) override;

  std::string name() const override { return "runaway"; }
  nlohmann::json save() override;
  void restore(const nlohmann::json& state) override;

  // Per trajectory, in job order; nothing for those that did not run off.
  std::vector<std::optional<Runaway>> runaways() const;

 private:
  // The largest scale after the first tenth, and where.
  struct Furthest {
    double scale = 0.0, t = 0.0;
  };
  // What is known of one trajectory.
  struct Watch {
    double reference_scale = 0.0;
    std::optional<double> largest_error;  // the largest |dH/H0| where H was evaluated; nothing while unknown
    std::optional<Furthest> furthest;     // after the first tenth; taken for a runaway where H is next evaluated
    std::optional<Runaway> runaway;
  };
  double reference_until_;
  std::uint64_t stride_;
  std::size_t n_;
  std::vector<double> initial_p_;          // per trajectory, its n initial momenta
  std::vector<Watch> watches_;             // per trajectory
  std::vector<std::vector<Watch>> saved_;  // per block: its trajectories' watches at the chunk's start

  void see_scale(std::size_t trajectory, double t, std::span<const double> q, std::span<const double> p);
  // Where H is evaluated: takes its error into the largest, then the furthest point so far for a runaway when it
  // is one and the error stayed small.
  void see_energy(std::size_t trajectory, std::optional<double> energy, std::optional<double> energy_initial);
};

// The sentence for one runaway: "|q| or |p| grew from 0.5 to 31 by t = 40 while |dH/H0| stayed at most 2e-06: the
// energy shell may be non-compact ...".
std::string runaway_text(const Runaway& runaway);

}  // namespace nonsep::host
