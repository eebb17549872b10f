#pragma once
// Triplet composition (Creutz-Gocksch, Yoshida), eqs. (sym43) and (sym63) of Chin's paper, applied
// recursively to any depth:
//
//   T_{(k+2)/3}(dt) = T_{k/3}(dt/(2-s)) T_{k/3}(-s dt/(2-s)) T_{k/3}(dt/(2-s)),   s = 2^(3/(k+3)),
//
// starting from the basic step T_{2/3} (k = 2). `levels` compositions give order 2(levels+1)/3 at the cost of
// 3^levels basic steps per step. The choice of s cancels the leading error term dt^((k+3)/3); the middle step
// runs backwards in time, which the real cube root in the basic step handles. Symplectic and time-reversible
// because every factor is.
//
// TripletComposition wraps a base stepper (any type with the ChinBasicStep interface) instead of copying it.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

template <class Base = ChinBasicStep>
class TripletComposition {
 public:
  static constexpr int max_levels = 12;  // 3^12 = 531441 basic steps per step

  // Throws InvalidArgument when levels is outside [0, max_levels].
  TripletComposition(Base base, int levels) : base_(std::move(base)), levels_(levels) {
    if (levels < 0 || levels > max_levels)
      throw InvalidArgument("triplet levels must be between 0 and " + std::to_string(max_levels) + " (found " +
                            std::to_string(levels) + ")");
  }
  // The composition of the requested order (2/3, 4/3, 2, 8/3, ...); throws InvalidArgument listing valid orders.
  static TripletComposition for_order(Base base, const Fraction& order) {
    return TripletComposition(std::move(base), chin_order_index(order, max_levels + 1, "triplet") - 1);
  }

  int levels() const { return levels_; }
  Fraction order() const { return description({}, levels_).order; }
  // The s of the composition that raises order k/3 = 2*level/3 to (k+2)/3.
  static double s_for_level(int level) { return std::pow(2.0, 3.0 / (2.0 * level + 3.0)); }

  const Base& base() const { return base_; }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  IntegratorDescription describe() const { return description(base_.describe(), levels_); }
  // The description of the composition of `levels` levels over a base step described by `base` (its scheme's,
  // chin_schemes.hpp, without building one).
  static IntegratorDescription description(IntegratorDescription base, int levels) {
    base.scheme = "triplet";
    base.order = Fraction(2 * (levels + 1), 3);
    base.basic_steps_per_step *= static_cast<std::uint64_t>(std::pow(3.0, levels));
    return base;
  }

  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    for_each_basic_step(levels_, dt, [&](double basic_dt) { base_.step(model, x, basic_dt); });
  }

  // n composed steps of dt: bit for bit n calls of step(model, x, dt). A base with step_schedule_n (ChinBasicStep,
  // SeparableComposition) takes the 3^levels basic steps of each composed step as one schedule, so that a model with
  // a kernel runs the n composed steps in one call.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if (n == 0) return;
    check_step_size(dt);
    schedule_.clear();
    for_each_basic_step(levels_, dt, [&](double basic_dt) { schedule_.push_back(basic_dt); });
    if constexpr (requires { base_.step_schedule_n(model, x, std::span<const double>(schedule_), n); }) {
      base_.step_schedule_n(model, x, std::span<const double>(schedule_), n);
    } else {
      for (std::uint64_t k = 0; k < n; ++k)
        for (double basic_dt : schedule_) base_.step(model, x, basic_dt);
    }
  }

  // Calls basic_step(dt_j) for the 3^levels basic steps of one composed step of dt, in order: the schedule of
  // the composition, shared with the tangent map (tangent_triplet_composition.hpp).
  template <class BasicStep>
  static void for_each_basic_step(int levels, double dt, BasicStep&& basic_step) {
    if (levels == 0) {
      basic_step(dt);
      return;
    }
    const double s = s_for_level(levels);
    const double outer = dt / (2.0 - s);
    for_each_basic_step(levels - 1, outer, basic_step);
    for_each_basic_step(levels - 1, -s * outer, basic_step);
    for_each_basic_step(levels - 1, outer, basic_step);
  }
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) {
    base_.prime(model, x);
  }

 private:
  Base base_;
  int levels_;
  std::vector<double> schedule_;  // step_n's basic step sizes, kept for their storage
};

}  // namespace nonsep
