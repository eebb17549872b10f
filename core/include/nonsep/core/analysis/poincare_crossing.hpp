#pragma once
// Locating the crossing of a trajectory with a surface of section, a hyperplane of phase space
//   s(q, p) = n_q . q + n_p . p - c = 0.
// A run that sees s change sign over one step of dt (from the state x at t to the state at t + dt) hands x, t
// and dt to locate(). The crossing is found on the numerical trajectory itself: the map tau -> x(tau) = one step
// of size tau from x (tau between 0 and dt, of either sign; the basic step and its compositions take any dt, a
// negative one running backwards through the real cube root), and the root tau* of s(x(tau)) is bracketed by
// Boost.Math's TOMS 748 solver (boost::math::tools::toms748_solve) to the last bits of tau. The result is the
// evaluated point with the smallest |s|, so |s| is at round-off level: |s| <= 1e-12 (|n| |(q, p)| + |c|) in the
// tests, which check that the point lies on the numerical flow (against the same scheme in fine steps).
//
// The stepper is any type with step(model, x, dt) (ChinBasicStep, TripletComposition, MultiProductExpansion,
// Integrator); use the run's own, so the crossing lies on the trajectory the run computes. Each evaluation is one
// step of one state; a crossing costs some 10 to 20 steps. Scratch states are members and reused.
//
// Errors: InvalidArgument for a normal of the wrong size or zero, a state of another dimension, dt not finite or
// zero, and when s does not change sign (or vanish) over the step: "no crossing in this step, s goes from ...".
// The model's exceptions propagate.
#include <boost/math/tools/toms748_solve.hpp>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

class SectionPlane {
 public:
  // normal: 2n numbers, n_q then n_p, not all zero.
  SectionPlane(std::vector<double> normal, double offset) : normal_(std::move(normal)), offset_(offset) {
    double squared = 0.0;
    for (double x : normal_) squared += x * x;
    if (normal_.empty() || normal_.size() % 2 != 0 || squared == 0.0 || !std::isfinite(squared) ||
        !std::isfinite(offset))
      throw InvalidArgument(
          "a section plane needs a finite, non-zero normal of 2n numbers (n for q, then n for p) "
          "and a finite offset (found " +
          std::to_string(normal_.size()) + " numbers)");
    norm_ = std::sqrt(squared);
  }

  std::size_t dimension() const { return normal_.size() / 2; }
  // s(q, p), for q and p of n numbers each.
  double distance(std::span<const double> q, std::span<const double> p) const {
    const std::size_t n = dimension();
    double s = -offset_;
    for (std::size_t i = 0; i < n; ++i) s += normal_[i] * q[i] + normal_[n + i] * p[i];
    return s;
  }
  // |n| |(q, p)| + |c|: the size of the terms s is made of, against which its round-off is measured.
  double scale(std::span<const double> q, std::span<const double> p) const {
    double squared = 0.0;
    for (std::size_t i = 0; i < dimension(); ++i) squared += q[i] * q[i] + p[i] * p[i];
    return norm_ * std::sqrt(squared) + std::abs(offset_);
  }

 private:
  std::vector<double> normal_;
  double offset_;
  double norm_ = 0.0;
};

// The point where a trajectory crosses the plane: time, q and p (n numbers each), and s there.
struct SectionCrossing {
  double time = 0.0;
  std::vector<double> q, p;
  double distance = 0.0;
  std::uint64_t steps = 0;  // fractional steps taken to find it
};

template <class Stepper = ChinBasicStep>
class PoincareCrossingLocator {
 public:
  explicit PoincareCrossingLocator(Stepper stepper = Stepper()) : stepper_(std::move(stepper)) {}

  const Stepper& stepper() const { return stepper_; }

  // The crossing within the step of dt from (q, p) at time t (errors above). Writes it into `crossing`, whose
  // vectors are reused.
  template <Model M>
  void locate(const M& model, std::span<const double> q, std::span<const double> p, double t, double dt,
              const SectionPlane& plane, SectionCrossing& crossing) {
    check_step_size(dt);
    const std::size_t n = q.size();
    if (p.size() != n || plane.dimension() != n || model.dimension() != n)
      throw InvalidArgument("the state has dimension " + std::to_string(q.size()) + ", the plane " +
                            std::to_string(plane.dimension()) + " and the model " + std::to_string(model.dimension()));
    if (start_.dimension() != n) {
      start_ = PhaseSpaceBatch(n, 1);
      trial_ = PhaseSpaceBatch(n, 1);
    }
    std::copy(q.begin(), q.end(), start_.q().begin());
    std::copy(p.begin(), p.end(), start_.p().begin());
    const double s_start = plane.distance(q, p);
    crossing.q.assign(q.begin(), q.end());
    crossing.p.assign(p.begin(), p.end());
    crossing.time = t;
    crossing.distance = s_start;
    crossing.steps = 0;
    // s after a step of tau; keeps the point of smallest |s| seen in `crossing`.
    auto s_after = [&](double tau) {
      if (tau == 0.0) return s_start;
      trial_ = start_;
      stepper_.step(model, trial_, tau);
      ++crossing.steps;
      const double s = plane.distance(trial_.q(), trial_.p());
      if (std::abs(s) < std::abs(crossing.distance) || std::isnan(crossing.distance)) {
        crossing.distance = s;
        crossing.time = t + tau;
        std::copy(trial_.q().begin(), trial_.q().end(), crossing.q.begin());
        std::copy(trial_.p().begin(), trial_.p().end(), crossing.p.begin());
      }
      return s;
    };
    const double s_end = s_after(dt);
    if (s_start == 0.0 || s_end == 0.0) return;
    if ((s_start < 0.0) == (s_end < 0.0) || std::isnan(s_start) || std::isnan(s_end))
      throw InvalidArgument("no crossing in this step, s goes from " + std::to_string(s_start) + " to " +
                            std::to_string(s_end));
    const double lower = std::min(0.0, dt), upper = std::max(0.0, dt);
    const double s_lower = dt < 0.0 ? s_end : s_start, s_upper = dt < 0.0 ? s_start : s_end;
    std::uintmax_t iterations = 100;
    boost::math::tools::toms748_solve(s_after, lower, upper, s_lower, s_upper,
                                      boost::math::tools::eps_tolerance<double>(), iterations);
  }

 private:
  Stepper stepper_;
  PhaseSpaceBatch start_, trial_;
};

}  // namespace nonsep
