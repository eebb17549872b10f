#pragma once
// MEGNO, the Mean Exponential Growth factor of Nearby Orbits (Cincotta and Simo, Astron. Astrophys. Suppl. 147,
// 205 (2000)): for a tangent vector delta(t),
//   Y(t) = (2/t) int_0^t (delta'(s)/delta(s)) s ds,     <Y>(t) = (1/t) int_0^t Y(s) ds.
// For the one-step map of a symplectic integrator the tangent vector is known only at the steps t_k, and the
// integrals become sums over the steps, as in REBOUND (Rein and Tamayo 2015; src/tools.c, megno_Ys and
// megno_Yss) and in the discrete MEGNO for maps (Cincotta, Giordano and Simo, Physica D 182, 151 (2003)):
//   Y(t_N)   = (2/t_N) sum_{k=1..N} t_k ln(|delta_k| / |delta_{k-1}|),
//   <Y>(t_N) = (1/t_N) sum_{k=1..N} Y(t_k) (t_k - t_{k-1}),
// the integrand delta'/delta ds replaced by the step's exact log-growth ln(|delta_k|/|delta_{k-1}|) (which the
// tangent map gives without a derivative of delta). With a constant dt, t_k = k dt and these are the map forms
// Y_N = (2/N) sum_k k ln(|delta_k|/|delta_{k-1}|), <Y>_N = (1/N) sum_k Y_k.
//
// Limits. Quasi-periodic orbit: the tangent vector grows linearly, |delta_k| ~ a k (shear between neighbouring
// tori), so ln(|delta_k|/|delta_{k-1}|) ~ 1/k, each term t_k ln(...) ~ dt, Y -> 2 and <Y> -> 2 (oscillations of
// Y are averaged out by <Y>). Chaotic orbit with largest exponent lambda: |delta_k| ~ exp(lambda t_k), each term is
// t_k lambda dt, so Y(t) ~ (2/t) lambda t^2/2 = lambda t and <Y>(t) ~ lambda t/2. Stable periodic orbit (delta
// bounded): Y, <Y> -> 0.
//
// The growth ln(|delta_k|/|delta_{k-1}|) is what LyapunovExponents::after_step hands out for its first vector,
// unaffected by its renormalisations. Per-trajectory state: one MegnoRecord per state, owned by the caller,
// trivially copyable, restored bit for bit from a checkpoint.
#include <span>
#include <string>

#include "nonsep/core/base/error.hpp"

namespace nonsep {

struct MegnoRecord {
  double time = 0.0;             // t_N
  double weighted_growth = 0.0;  // sum_k t_k ln(|delta_k| / |delta_{k-1}|)
  double integrated_y = 0.0;     // sum_k Y(t_k) (t_k - t_{k-1})

  // One step of dt whose log-growth of the tangent vector was `growth`.
  void add_step(double growth, double dt) {
    time += dt;
    weighted_growth += time * growth;
    integrated_y += y() * dt;
  }
  double y() const { return time == 0.0 ? 0.0 : 2.0 * weighted_growth / time; }
  double mean_y() const { return time == 0.0 ? 0.0 : integrated_y / time; }
  friend bool operator==(const MegnoRecord&, const MegnoRecord&) = default;
};

// add_step on each record: records[b] gets growth[b] and the common dt. Throws InvalidArgument when the spans
// differ in size.
inline void add_megno_step(std::span<MegnoRecord> records, std::span<const double> growth, double dt) {
  if (records.size() != growth.size())
    throw InvalidArgument("MEGNO: " + std::to_string(records.size()) + " records but " + std::to_string(growth.size()) +
                          " growth values");
  for (std::size_t b = 0; b < records.size(); ++b) records[b].add_step(growth[b], dt);
}

}  // namespace nonsep
