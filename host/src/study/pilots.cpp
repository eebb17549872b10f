// Scheme "auto"'s pilots: the ladders of each candidate and the prediction from them (pilots.hpp).
#include "pilots.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "pilot_run.hpp"

namespace nonsep::host {

namespace {

using Clock = std::chrono::steady_clock;

// Below this a pilot's error is round-off (relative to the state's length for the phase error).
constexpr double pilot_round_off = 1e-13;
// The round-off of the phase error as an orbit amplifies it: measured (twins_round_off) where the error falls more
// slowly than the order and is below this, relative to the state's length.
constexpr double measure_round_off_below = 1e-8;
// A pilot pair at round-off differs by up to about twice the larger of the twins' distances (paper2d's regular
// orbits to t = 100 with Gauss 16, 2048 to 32768 steps); this factor keeps a margin.
constexpr double round_off_twin_factor = 4.0;
// The asymptotic range: the error falls by 2^order per halving of the step, within this factor.
constexpr double asymptotic_within = 2.5;
class Pilots {
 public:
  Pilots(const LoadedJob& loaded, const RunOptions& options, SchemeChoice& choice, double fraction)
      : loaded_(loaded), options_(options), choice_(choice), run_(loaded.job.run()) {
    const InitialStates& initial = loaded.job.initial;
    const std::size_t n = initial.dimension;
    const std::vector<std::size_t> indices = pilot_indices(initial);
    std::vector<std::size_t> set_of;  // each pilot state's parameter set (empty without a sweep)
    for (const std::size_t index : indices) {
      if (!initial.parameter_set.empty()) set_of.push_back(initial.parameter_set[index]);
      q_.insert(q_.end(), initial.q.begin() + static_cast<std::ptrdiff_t>(index * n),
                initial.q.begin() + static_cast<std::ptrdiff_t>(index * n + n));
      p_.insert(p_.end(), initial.p.begin() + static_cast<std::ptrdiff_t>(index * n),
                initial.p.begin() + static_cast<std::ptrdiff_t>(index * n + n));
    }
    // Each pilot state is stepped with its own set's parameters, as the run steps it.
    sets_ = parameter_sets(loaded.job, set_of);
    choice_.pilot_states = indices.size();
    choice_.pilot_horizon = run_.time.t_end / fraction;
  }

  // `bound`: the least predicted cost of the candidates measured so far; a candidate whose pilots take longer is
  // left out (its run could not be cheaper than that one's pilots and run together).
  PilotResult measure(const AutoCandidate& candidate, std::optional<double> bound) {
    const double spent_before = choice_.pilot_seconds;
    PilotResult result;
    result.candidate = candidate;
    const double order = Integrator::describe(candidate.spec).order.value();
    const bool energy = choice_.measure == AutoScheme::Measure::energy;
    const std::size_t width = 2 * loaded_.job.initial.dimension;
    std::map<std::uint64_t, PilotRun> runs, twins;
    const PilotRun over;  // a pilot not run: it would have taken the candidate's pilots over the bound
    // Over the bound: what the pilots took, and what the next one would take at the last one's seconds per step.
    double per_step = 0.0;
    const auto over_bound = [&](std::uint64_t next_steps) {
      return bound && choice_.pilot_seconds - spent_before + per_step * static_cast<double>(next_steps) > *bound;
    };
    const auto run = [&](std::uint64_t steps, bool twin = false) -> const PilotRun& {
      std::map<std::uint64_t, PilotRun>& into = twin ? twins : runs;
      auto found = into.find(steps);
      if (found == into.end() && !over_bound(steps)) {
        found = into.emplace(steps, pilot(candidate.spec, steps, energy, twin)).first;
        per_step = found->second.seconds / static_cast<double>(steps);
      }
      return found == into.end() ? over : found->second;
    };
    // The round-off of the pilots r2 and r4 (2n and 4n steps) at t_p as the orbit amplifies it: their distances from
    // their twins (the same runs with a step one ulp larger: every step rounds differently, the truncation error is
    // the same to a relative 1e-16), the larger times round_off_twin_factor. Nothing when a twin was not run (over
    // the bound) or had a problem.
    const auto twins_round_off = [&](std::uint64_t n, const PilotRun& r2, const PilotRun& r4) -> std::optional<double> {
      const PilotRun &t2 = run(2 * n, true), &t4 = run(4 * n, true);
      if (&t2 == &over || &t4 == &over || !t2.problem.empty() || !t4.problem.empty()) return std::nullopt;
      return round_off_twin_factor * std::max(largest_distance(r2.marks.back(), t2.marks.back(), width),
                                              largest_distance(r4.marks.back(), t4.marks.back(), width));
    };
    std::string last;
    for (std::uint64_t n = 4; 4 * n <= auto_pilot_max_steps; n *= 2) {
      const PilotRun &r1 = run(n), &r2 = run(2 * n), &r4 = run(4 * n);
      if (&r1 == &over || &r2 == &over || &r4 == &over) {
        result.excluded = "its pilots took " + format_number(choice_.pilot_seconds - spent_before) +
                          " s, and the next would take them past the predicted run of a candidate before it (" +
                          format_number(*bound) + " s)";
        return result;
      }
      if (!r1.problem.empty() || !r2.problem.empty() || !r4.problem.empty()) {
        last = "its pilot with " +
               std::to_string(!r1.problem.empty()   ? n
                              : !r2.problem.empty() ? 2 * n
                                                    : 4 * n) +
               " steps " +
               (!r1.problem.empty()   ? r1.problem
                : !r2.problem.empty() ? r2.problem
                                      : r4.problem);
        continue;
      }
      const double coarse = energy ? r2.max_end : largest_distance(r1.marks.back(), r2.marks.back(), width);
      const double fine = energy ? r4.max_end : largest_distance(r2.marks.back(), r4.marks.back(), width);
      const double length = energy ? 1.0 : std::max(1.0, largest_length(r4.marks.back(), width));
      const double ratio = coarse / fine, expected = std::pow(2.0, order);
      // The phase error's round-off grows with the orbit's sensitivity, not only with the state's length (paper2d's
      // regular orbit q = (0, 0), p = (0.5, 2) to t = 100: 1e-12 to 4e-12 by Gauss 16 at 2^11 to 2^15 steps, 5 to 20
      // times the fixed bound): where a small error falls more slowly than the order, the twins measure it.
      double floor = pilot_round_off * length;
      if (!energy && fine > floor && fine <= measure_round_off_below * length && ratio < expected / asymptotic_within)
        if (const auto measured = twins_round_off(n, r2, r4)) floor = std::max(floor, *measured);
      const bool round_off = fine <= floor;
      if (!round_off && !(ratio >= expected / asymptotic_within && ratio <= expected * asymptotic_within)) {
        last = "its error fell by " + format_number(ratio) + " from " + std::to_string(2 * n) + " to " +
               std::to_string(4 * n) + " pilot steps, not by 2^order = " + format_number(expected);
        if (const auto least = least_run_seconds(order, energy ? 4 * n : 2 * n, fine, r2, r4, n);
            bound && least && *least > *bound) {
          result.excluded =
              "its pilots' error, " + format_number(fine) + " at " + std::to_string(energy ? 4 * n : 2 * n) +
              " steps, falling even at twice its order would need a run of at least " + format_number(*least) +
              " s, longer than the predicted run of a candidate before it (" + format_number(*bound) + " s)";
          return result;
        }
        continue;
      }
      result.pilot_steps = n;
      result.ratio = ratio;
      result.round_off = floor;
      if (floor > pilot_round_off * length) choice_.amplified_round_off = std::max(choice_.amplified_round_off, floor);
      // The pair whose difference is the error (energy: the run whose error it is) and where the prediction starts.
      // When the finest run's error is round-off, the coarser pair measures the error of its coarser run (phase: the
      // n run's, within the 2n run's error, which is round-off; energy: the 2n run's own): the prediction starts
      // there, at a measured error, or at the round-off bound when that pair is within it too (the first ladder
      // without a problem, all of it at round-off), rather than at the 4n run's round-off bound. The rate towards
      // smaller steps is then the one observed down to round-off, which that round-off can only make slower (a
      // larger predicted error).
      const PilotRun &pair_coarse = round_off ? r1 : r2, &pair_fine = round_off ? r2 : r4;
      result.anchor_steps = round_off ? (energy ? 2 * n : n) : 4 * n;
      result.pilot_dt = choice_.pilot_horizon / static_cast<double>(result.anchor_steps);
      // At round-off the difference bounds the error; in the asymptotic range Richardson gives it.
      result.pilot_error = round_off ? std::max(coarse, floor) : energy ? fine : fine / (expected - 1.0);
      const double end = round_off ? coarse : fine;
      const double half = energy ? pair_fine.max_half
                                 : largest_distance(pair_coarse.marks[pilot_marks / 2 - 1],
                                                    pair_fine.marks[pilot_marks / 2 - 1], width);
      const double raw = half > 0.0 && end > 0.0 ? std::log2(end / half) : 1.0;
      result.growth = std::clamp(std::isfinite(raw) ? raw : 1.0, energy ? 0.0 : 1.0, max_growth_exponent);
      // Where that pair is at round-off by t_p / 2, the next coarser pair of the candidate's pilots that is not (and
      // had no problem) still sees how the error grows: a chaotic orbit is then found by this candidate alone,
      // whichever others the pilots' time bound leaves out.
      if (!energy) {
        result.envelope_growth = envelope_growth(pair_coarse, pair_fine, width, floor);
        for (std::uint64_t steps = round_off ? n : 2 * n; !result.envelope_growth && steps >= 8; steps /= 2) {
          const auto coarser = runs.find(steps / 2), finer = runs.find(steps);
          if (coarser == runs.end() || finer == runs.end() || !coarser->second.problem.empty() ||
              !finer->second.problem.empty())
            break;
          result.envelope_growth = envelope_growth(coarser->second, finer->second, width, floor);
        }
      }
      result.seconds_per_step = r4.seconds > r1.seconds ? (r4.seconds - r1.seconds) / static_cast<double>(3 * n)
                                                        : r4.seconds / static_cast<double>(4 * n);
      predict(result, order);
      apply_round_off(result);
      return result;
    }
    result.excluded = "no usable pilot up to " + std::to_string(auto_pilot_max_steps) + " steps: " + last;
    return result;
  }

 private:
  // A lower bound on the run of a candidate whose ladder is not yet asymptotic, from its error `error` at `steps`
  // pilot steps: its error falling like h^(2 order) from there (faster than any of its ladders has fallen in the
  // catalogue's measurements), and growing no slower than the least exponent the prediction allows. Its seconds per
  // step are those between the 2n and the 4n pilot (the pilot's fixed cost cancels); nothing when they are not
  // measurable or the error already meets the tolerance.
  std::optional<double> least_run_seconds(double order, std::uint64_t steps, double error, const PilotRun& r2,
                                          const PilotRun& r4, std::uint64_t n) const {
    const double per_step = (r4.seconds - r2.seconds) / static_cast<double>(2 * n);
    const double horizons = std::abs(run_.time.t_end / choice_.pilot_horizon);
    const double target =
        choice_.tolerance / (auto_safety * (choice_.measure == AutoScheme::Measure::energy ? 1.0 : horizons));
    if (!(per_step > 0.0) || !(error > target) || !std::isfinite(error)) return std::nullopt;
    const double pilot_steps = static_cast<double>(steps) * std::pow(error / target, 1.0 / (2.0 * order));
    return per_step * pilot_steps * horizons * static_cast<double>(loaded_.job.initial.count) /
           static_cast<double>(choice_.pilot_states);
  }

  // The largest step |time.dt| / m that meets tolerance / auto_safety by the prediction, and its cost.
  void predict(PilotResult& result, double order) const {
    const TimeGrid& time = run_.time;
    const double growth = std::pow(std::abs(time.t_end / choice_.pilot_horizon), result.growth);
    const double h_pilot = std::abs(result.pilot_dt);
    // Where the pilots' errors fell more slowly than 2^order per halving (not yet asymptotic), extrapolating to a
    // smaller step uses the slower observed rate; to a larger step the order (either way the larger prediction).
    const double observed = result.ratio > 1.0 ? std::log2(result.ratio) : order;
    const double smaller = std::min(order, observed), larger = std::max(order, observed);
    // The aim: a third of the tolerance, or the measured round-off where that is larger (apply_round_off: smaller
    // steps than those that reach it gain nothing).
    const double aim = std::max(choice_.tolerance / auto_safety, choice_.amplified_round_off * growth);
    double rate = smaller;
    double h_max = h_pilot * std::pow(aim / (result.pilot_error * growth), 1.0 / rate);
    if (h_max > h_pilot) {
      rate = larger;
      h_max = std::max(h_pilot, h_pilot * std::pow(aim / (result.pilot_error * growth), 1.0 / rate));
    }
    // No larger than the coarsest pilot step the accepted ladder covers (t_p / n): above it the pilots showed no
    // asymptotic fall (the ladder from n / 2 was not accepted), and the iteration of an implicit scheme may diverge.
    h_max = std::min(h_max, std::abs(choice_.pilot_horizon) / static_cast<double>(result.pilot_steps));
    const double m = std::max(1.0, std::ceil(std::abs(time.dt) / h_max * (1.0 - 1e-12)));
    const double steps = static_cast<double>(time.steps) * m;
    if (!(steps <= static_cast<double>(max_steps))) {
      result.excluded = "it would need " + format_number(steps) + " steps, more than " + std::to_string(max_steps);
      return;
    }
    result.steps = static_cast<std::uint64_t>(steps);
    const double h = std::abs(time.dt) / m;
    result.predicted_error = result.pilot_error * std::pow(h / h_pilot, h < h_pilot ? smaller : larger) * growth;
    result.predicted_seconds = result.seconds_per_step * steps * static_cast<double>(loaded_.job.initial.count) /
                               static_cast<double>(choice_.pilot_states);
  }

 public:
  // The round-off the pilots measured (twins_round_off, above the fixed bound: the orbit amplifies each step's
  // rounding; the largest over the candidates so far, for it is the orbit's more than the scheme's) does not fall
  // with the step: no prediction of a usable candidate goes below it, grown to t_end as its error grows. A
  // tolerance below it is not met by any step, and the prediction says so (the run warns; the candidate stays, the
  // best double precision gives). run_pilots applies it again once every candidate is measured, to those measured
  // before it was known.
  void apply_round_off(PilotResult& result) const {
    if (!result.excluded.empty() || choice_.amplified_round_off == 0.0) return;
    const double at_end =
        choice_.amplified_round_off * std::pow(std::abs(run_.time.t_end / choice_.pilot_horizon), result.growth);
    result.predicted_error = std::max(result.predicted_error, at_end);
  }

 private:
  // A pilot of `steps` steps to t_p; a twin's step is one ulp larger (it ends later by `steps` ulps of the step,
  // about 1e-16 t_p, which moves its end point by that times the speed: far below the round-off it measures).
  PilotRun pilot(const IntegratorSpec& spec, std::uint64_t steps, bool energy, bool twin = false) {
    const std::size_t count = choice_.pilot_states;
    const double t_p = choice_.pilot_horizon, dt = t_p / static_cast<double>(steps);
    EnsembleSetup setup{
        spec,
        twin ? TimeGrid::of_steps(steps, std::nextafter(dt, 2.0 * dt)) : TimeGrid::to_end(t_p, dt, steps),
        loaded_.job.initial.dimension,
        q_,
        p_,
        options_.threads,
        options_.stop_requested};
    setup.parameter_sets = sets_;
    EnsembleDriver driver(loaded_.plugin, loaded_.model, setup);
    PilotObserver observer(count, loaded_.job.initial.dimension, steps, energy);
    driver.add_observer(observer);
    const auto start = Clock::now();
    const DriverEnd end = driver.run();
    PilotRun result;
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    choice_.pilot_seconds += result.seconds;
    choice_.pilot_state_steps += steps * count;
    const EvaluationCounts e = driver.evaluations();
    EvaluationCounts& total = choice_.pilot_evaluations;
    total.grad_T += e.grad_T;
    total.grad_V += e.grad_V;
    total.grad_H += e.grad_H;
    total.grad_K += e.grad_K;
    total.grad_U += e.grad_U;
    if (end == DriverEnd::interrupted) throw PilotsInterrupted("interrupted during the pilot runs of scheme auto");
    if (end == DriverEnd::failed) result.problem = "failed: " + driver.error();
    if (result.problem.empty()) result.problem = observer.problem_;
    result.marks = std::move(observer.marks_);
    result.max_half = observer.max_half_;
    result.max_end = observer.max_end_;
    return result;
  }

  const LoadedJob& loaded_;
  const RunOptions& options_;
  SchemeChoice& choice_;
  const SingleRun& run_;
  std::vector<double> q_, p_;
  std::vector<ParameterSet> sets_;  // of the pilot states; empty without a sweep
};

}  // namespace

std::vector<std::size_t> pilot_indices(const InitialStates& initial) {
  const std::vector<std::size_t>& set_of = initial.parameter_set;
  std::vector<std::pair<std::size_t, std::size_t>> sets;  // each set's states: [first, end)
  for (std::size_t b = 0; b < initial.count; ++b) {
    if (b == 0 || (!set_of.empty() && set_of[b] != set_of[b - 1]))
      sets.emplace_back(b, b + 1);
    else
      sets.back().second = b + 1;
  }
  std::vector<std::size_t> indices;
  const std::size_t each = sets.empty() ? 0 : std::max<std::size_t>(1, auto_pilot_states / sets.size());
  for (const auto& [first, end] : sets) {
    const std::size_t size = end - first, count = std::min(size, each);
    // The set's first and last states among them: on a grid the extremes are often the hardest (the largest
    // amplitude, the parameter's end).
    for (std::size_t k = 0; k < count; ++k) indices.push_back(first + (count == 1 ? 0 : k * (size - 1) / (count - 1)));
  }
  return indices;
}

void run_pilots(const LoadedJob& loaded, const RunOptions& options, SchemeChoice& choice, double fraction) {
  choice.pilots.clear();
  choice.amplified_round_off = 0.0;
  Pilots pilots(loaded, options, choice, fraction);
  std::optional<double> bound;
  for (const AutoCandidate& candidate : auto_candidates(loaded)) {
    choice.pilots.push_back(pilots.measure(candidate, bound));
    if (const PilotResult& last = choice.pilots.back(); last.excluded.empty())
      bound = std::min(bound.value_or(last.predicted_seconds), last.predicted_seconds);
  }
  for (PilotResult& result : choice.pilots) pilots.apply_round_off(result);
}

}  // namespace nonsep::host
