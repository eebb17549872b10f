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

#include "nonsep/core/analysis/indicator.hpp"
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

// MEGNO as an indicator (indicator.hpp): columns megno (Y) and mean_megno (<Y>); state: a MegnoRecord's three
// numbers (time, weighted_growth, integrated_y).
class MegnoIndicator final : public Indicator {
 public:
  std::string name() const override { return "megno"; }
  IndicatorNeeds needs() const override { return {.tangent_vectors = 1, .first_growth = true, .state_size = 3}; }
  std::vector<std::string> columns() const override { return {"megno", "mean_megno"}; }
  std::string description() const override {
    return "trajectories.csv megno (Y), mean_megno (<Y>, -> 2 on quasi-periodic orbits)";
  }
  void start(std::span<double> state) const override { store(MegnoRecord{}, state); }
  void after_step(std::span<double> state, double growth, double dt) const override {
    MegnoRecord record = load(state);
    record.add_step(growth, dt);
    store(record, state);
  }
  void values(std::span<const double> state, const LyapunovRecord&, std::span<double> out) const override {
    const MegnoRecord record = load(state);
    out[0] = record.y();
    out[1] = record.mean_y();
  }

 private:
  static MegnoRecord load(std::span<const double> state) { return {state[0], state[1], state[2]}; }
  static void store(const MegnoRecord& record, std::span<double> state) {
    state[0] = record.time;
    state[1] = record.weighted_growth;
    state[2] = record.integrated_y;
  }
};

}  // namespace nonsep
