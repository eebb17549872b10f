#pragma once
// What one pilot run of scheme "auto" keeps (pilots.cpp): its states at fixed marks and its energy errors, recorded by
// an observer of the run, and the distances between such runs that the pilots compare.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/run/ensemble_driver.hpp"

namespace nonsep::host {

// The pilots' states are kept at t_p k / pilot_marks (k = 1 .. pilot_marks), for the growth of the phase error.
constexpr std::uint64_t pilot_marks = 8;

// One pilot run: its states at t_p k / pilot_marks (k = 1 .. pilot_marks; those that fall on a step) and its largest
// |dH/H0| up to t_p / 2 and t_p (energy evaluated at every step when the measure is the energy).
class PilotObserver : public Observer {
 public:
  PilotObserver(std::size_t count, std::size_t dimension, std::uint64_t steps, bool energy)
      : dimension_(dimension), steps_(steps), energy_(energy), width_(count * 2 * dimension), marks_(pilot_marks) {}

  std::uint64_t next_event(std::uint64_t step) const override {
    if (energy_) return step < steps_ ? step + 1 : no_event;
    for (std::uint64_t k = 1; k <= pilot_marks; ++k)
      if (const auto mark = mark_step(k); mark && *mark > step) return *mark;
    return no_event;
  }
  bool needs_energy(std::uint64_t) const override { return energy_; }
  void on_event(const Event& event) override {
    for (const StateView& state : event.states) {
      if (energy_ && state.energy && state.record->energy_initial && *state.record->energy_initial != 0.0) {
        const double e = std::abs((*state.energy - *state.record->energy_initial) / *state.record->energy_initial);
        max_end_ = std::max(max_end_, e);
        if (event.step <= steps_ / 2) max_half_ = std::max(max_half_, e);
      }
      const std::uint64_t k = event.step * pilot_marks / steps_;
      if (k == 0 || mark_step(k) != event.step) continue;
      std::vector<double>& into = marks_[k - 1];
      into.resize(width_);
      std::copy(state.q.begin(), state.q.end(),
                into.begin() + static_cast<std::ptrdiff_t>(state.trajectory * 2 * dimension_));
      std::copy(state.p.begin(), state.p.end(),
                into.begin() + static_cast<std::ptrdiff_t>(state.trajectory * 2 * dimension_ + dimension_));
    }
  }
  void on_retire(std::size_t trajectory, const TrajectoryRecord& record) override {
    if (stopped_early(record.status) && problem_.empty())
      problem_ = std::string(to_string(record.status)) + " at step " + std::to_string(record.stop_step) +
                 " (pilot state " + std::to_string(trajectory) + ")";
  }

  // The step of mark k, when t_p k / pilot_marks falls on one.
  std::optional<std::uint64_t> mark_step(std::uint64_t k) const {
    if (k * steps_ % pilot_marks != 0) return std::nullopt;
    return k * steps_ / pilot_marks;
  }

  std::size_t dimension_;
  std::uint64_t steps_;
  bool energy_;
  std::size_t width_;
  std::vector<std::vector<double>> marks_;  // the states at mark k = 1 .. pilot_marks; empty where none falls
  double max_half_ = 0.0, max_end_ = 0.0;
  std::string problem_;
};

struct PilotRun {
  std::string problem;                     // "" when every pilot state completed
  std::vector<std::vector<double>> marks;  // PilotObserver::marks_
  double max_half = 0.0, max_end = 0.0;
  double seconds = 0.0;
};

// The largest distance between the pilot states of two runs, and the largest length of a state.
inline double largest_distance(const std::vector<double>& a, const std::vector<double>& b, std::size_t width) {
  double largest = 0.0;
  for (std::size_t s = 0; s * width < a.size(); ++s) {
    double sum = 0.0;
    for (std::size_t i = 0; i < width; ++i)
      sum += (a[s * width + i] - b[s * width + i]) * (a[s * width + i] - b[s * width + i]);
    largest = std::max(largest, std::sqrt(sum));
  }
  return largest;
}

inline double largest_length(const std::vector<double>& a, std::size_t width) {
  return largest_distance(a, std::vector<double>(a.size(), 0.0), width);
}

// How the phase error of the pilot pair (2n, 4n steps) grew over the second half of the pilot: log2 of the largest
// distance between their states at the marks up to t_p over the largest up to t_p / 2. Nothing when that at t_p / 2
// is within a factor 10 of round-off (`floor`): the ratio of two round-offs says nothing about the orbit.
inline std::optional<double> envelope_growth(const PilotRun& coarse, const PilotRun& fine, std::size_t width,
                                             double floor) {
  double largest = 0.0, at_half = 0.0;
  for (std::size_t k = 0; k < pilot_marks; ++k) {
    largest = std::max(largest, largest_distance(coarse.marks[k], fine.marks[k], width));
    if (k + 1 == pilot_marks / 2) at_half = largest;
  }
  if (!(at_half > 10.0 * floor)) return std::nullopt;
  return std::log2(largest / at_half);
}

}  // namespace nonsep::host
