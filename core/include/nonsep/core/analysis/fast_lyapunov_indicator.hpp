#pragma once
// The fast Lyapunov indicator (Froeschle, Lega and Gonczi, Celest. Mech. Dyn. Astron. 67, 41 (1997); Lega, Guzzo and
// Froeschle, in Chaos Detection and Predictability, Lect. Notes Phys. 915, 35 (2016)): for a tangent vector w(t) of
// unit length at t = 0,
//   FLI(t) = sup_{0 <= s <= t} ln |w(s)|,
// the supremum taken over the steps, where the tangent map gives w exactly at the scheme's order. Natural logarithms.
// On a chaotic orbit FLI(t) ~ lambda t; on a regular orbit of a twist (shearing) torus family the vector grows
// linearly, FLI(t) ~ ln t; near a stable periodic orbit it stays bounded. Orbits are told apart by comparing FLI at a
// common time with ln t: far above it, chaotic. The vector is the first of the run's tangent vectors; its
// re-orthonormalisations do not change ln |w|, which is the sum of the first vector's log-growth over the steps
// (LyapunovExponents::after_step's first_growth).
//
// As an indicator (indicator.hpp): column fli; state: ln |w| now and its supremum so far.
#include <algorithm>

#include "nonsep/core/analysis/indicator.hpp"

namespace nonsep {

class FastLyapunovIndicator final : public Indicator {
 public:
  std::string name() const override { return "fli"; }
  IndicatorNeeds needs() const override { return {.tangent_vectors = 1, .first_growth = true, .state_size = 2}; }
  std::vector<std::string> columns() const override { return {"fli"}; }
  std::string description() const override {
    return "trajectories.csv fli: sup over the steps of ln |w| of the first tangent vector (|w(0)| = 1): ~ lambda t "
           "on chaotic orbits, ~ ln t on regular ones";
  }
  void start(std::span<double> state) const override {
    state[0] = 0.0;  // ln |w(0)|
    state[1] = 0.0;
  }
  void after_step(std::span<double> state, double growth, double) const override {
    state[0] += growth;
    state[1] = std::max(state[1], state[0]);
  }
  void values(std::span<const double> state, const LyapunovRecord&, std::span<double> out) const override {
    out[0] = state[1];
  }
};

}  // namespace nonsep
