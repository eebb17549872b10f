#pragma once
// The orthogonal fast Lyapunov indicator (Fouchard, Lega, Froeschle and Froeschle, Celest. Mech. Dyn. Astron. 83,
// 205 (2002)): for a tangent vector w(t) orthogonal to the flow at t = 0 and of unit length,
//   OFLI(t) = sup_{0 <= s <= t} ln |w_perp(s)|,
// w_perp(s) the component of w(s) orthogonal to the flow direction f = J grad H at the state (Euclidean, over
// (dq, dp)), the supremum taken over the steps. The part of the growth along the flow, which makes FLI grow like
// ln t on every regular orbit, is left out: on a periodic orbit (every orbit of one degree of freedom, resonant
// orbits) OFLI stays bounded; on a regular orbit of a shearing family of tori it grows like ln t (the shear across
// the flow remains); on a chaotic orbit like lambda t, as FLI.
//
// The vector is the run's first tangent vector v with its component along the flow removed: the tangent map takes
// the flow direction to itself (D phi_t f(x_0) = f(x_t)), so if v = v_perp + c f(x_0), the component of D phi_t v
// across f(x_t) is that of D phi_t v_perp, and
//   ln |w_perp(t)| = ln |v(t)| + a(t) - a(0),     a = ln(|v_perp| / |v|),
// with ln |v(t)| the sum of the first vector's log-growth (as FLI's) and a from the flow direction at the steps
// (IndicatorNeeds::across_flow: one gradient of H per state and step). The numerical map takes f to itself only to
// the scheme's order, so OFLI is right to that order. Natural logarithms; OFLI(0) = 0.
//
// As an indicator (indicator.hpp): column ofli; state: ln |v| now, a(0), and the supremum so far.
#include <algorithm>
#include <cmath>

#include "nonsep/core/analysis/indicator.hpp"

namespace nonsep {

class OrthogonalFastLyapunovIndicator final : public Indicator {
 public:
  std::string name() const override { return "ofli"; }
  IndicatorNeeds needs() const override {
    return {.tangent_vectors = 1, .first_growth = true, .across_flow = true, .state_size = 3};
  }
  std::vector<std::string> columns() const override { return {"ofli"}; }
  std::string description() const override {
    return "trajectories.csv ofli: sup over the steps of ln |w_perp| of the first tangent vector's component "
           "across the flow (|w_perp(0)| = 1): ~ lambda t on chaotic orbits, ~ ln t on regular ones, bounded on "
           "periodic ones";
  }
  void start(std::span<double> state) const override {
    state[0] = 0.0;  // ln |v(0)|
    state[1] = 0.0;  // a(0), set by across_flow at time 0
    state[2] = 0.0;  // OFLI(0)
  }
  void after_step(std::span<double> state, double growth, double) const override { state[0] += growth; }
  void across_flow(std::span<double> state, double a, bool at_start) const override {
    if (at_start) {
      state[1] = a;
      return;
    }
    const double value = state[0] + a - state[1];
    if (value > state[2]) state[2] = value;  // a NaN (grad H failed: the state retires) leaves the supremum
  }
  void values(std::span<const double> state, const LyapunovRecord&, std::span<double> out) const override {
    out[0] = state[2];
  }
};

}  // namespace nonsep
