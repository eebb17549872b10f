#pragma once
// MEGNO, the Mean Exponential Growth factor of Nearby Orbits (Cincotta and Simo, Astron. Astrophys. Suppl. 147,
// 205 (2000)): for a tangent vector w(t) of unit length at t = 0 and L(t) = ln |w(t)|,
//   Y(t) = (2/t) int_0^t s L'(s) ds,     <Y>(t) = (1/t) int_0^t Y(s) ds.
// Integrated by parts (L(0) = 0), with I1(t) = int_0^t L ds and I2(t) = int_0^t I1(s)/s ds,
//   Y(t) = 2 L(t) - (2/t) I1(t),          <Y>(t) = (2/t) (I1(t) - I2(t)),
// which need L at the steps only, and the tangent map gives L(t_k) = ln |w_k| at the scheme's order (the sum of the
// first vector's log-growth over the steps, unaffected by the re-orthonormalisations). Both integrands are smooth
// (I1(s)/s -> L(0) = 0 as s -> 0), so the quadratures can follow the scheme's order: here Gregory's rule of order
// 10 (the trapezoidal rule with end corrections of K = 9 points, exact for polynomials of degree 9 and valid from
// N = K - 1 = 8 steps on; the coefficients are those of the end corrections derived from the Euler-Maclaurin
// formula, Fornberg, BIT 61, 831 (2021)). I1 at the first steps t_1 .. t_7 comes from the polynomial through
// L_0 .. L_8, once L_8 is known, so that every I1(t_j)/t_j entering I2 has the rule's order; before step 8 the
// values are those of the polynomial through the steps so far (lower order, for the first 8 steps' outputs only).
// With a scheme of order p <= 10 the error of Y and <Y> is then O(dt^p), the scheme's; with Gauss-Legendre of more
// than 5 stages it is O(dt^10). The running sums are compensated (Neumaier), so long runs lose no digits to them.
//
// Limits. Quasi-periodic orbit: |w| grows linearly (shear between neighbouring tori), L ~ ln t, so Y -> 2 and
// <Y> -> 2 (oscillations of Y are averaged out by <Y>). Chaotic orbit with largest exponent lambda: L ~ lambda t,
// Y ~ lambda t and <Y> ~ lambda t / 2. Stable periodic orbit (|w| bounded): Y, <Y> -> 0. Over the first periods Y
// and <Y> can lie anywhere (negative included).
//
// As an indicator (indicator.hpp): columns megno (Y) and mean_megno (<Y>), a constant step dt; state: state_size
// numbers per trajectory (the layout below), restored bit for bit from a checkpoint.
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"

namespace nonsep {

class MegnoIndicator final : public Indicator {
 public:
  static constexpr std::size_t points = 9;  // K: the points of each end correction
  static constexpr std::size_t state_numbers = 45;

  std::string name() const override { return "megno"; }
  IndicatorNeeds needs() const override {
    return {.tangent_vectors = 1, .first_growth = true, .state_size = state_numbers};
  }
  std::vector<std::string> columns() const override { return {"megno", "mean_megno"}; }
  std::string description() const override {
    return "trajectories.csv megno (Y), mean_megno (<Y>, -> 2 on quasi-periodic orbits), by quadratures of order 10 "
           "of ln |w| at the steps";
  }

  void start(std::span<double> state) const override {
    for (double& x : state) x = 0.0;
  }

  void after_step(std::span<double> state, double growth, double dt) const override {
    const auto n = static_cast<std::size_t>(state[steps]) + 1;
    state[steps] = static_cast<double>(n);
    state[step] = dt;
    state[log_norm] += growth;
    const double l = state[log_norm];
    add(state, sum_l, l);
    state[ring_l + n % points] = l;
    if (n < points) state[first_l + n] = l;
    if (n < points - 1) return early(state, n);
    if (n == points - 1) finish_start(state);
    const double h = dt, t = static_cast<double>(n) * h;
    state[i1] = h * gregory(state, sum_l, first_l, ring_l, n);
    if (n > points - 1) {
      const double g = state[i1] / t;
      add(state, sum_g, g);
      state[ring_g + n % points] = g;
    }
    state[i2] = h * gregory(state, sum_g, first_g, ring_g, n);
  }

  void values(std::span<const double> state, const LyapunovRecord&, std::span<double> out) const override {
    const double t = state[steps] * state[step];
    out[0] = t == 0.0 ? 0.0 : 2.0 * state[log_norm] - 2.0 * state[i1] / t;
    out[1] = t == 0.0 ? 0.0 : 2.0 * (state[i1] - state[i2]) / t;
  }

 private:
  // The state's layout.
  static constexpr std::size_t steps = 0, step = 1, log_norm = 2, sum_l = 3, sum_g = 5, i1 = 7, i2 = 8, first_l = 9,
                               first_g = first_l + points, ring_l = first_g + points, ring_g = ring_l + points;
  static_assert(ring_g + points == state_numbers);

  // Gregory's end corrections c_j (j < 9): the weights of f_j and f_(N-j) are 1 - c_j (trapezoidal: c_0 = 1/2 alone).
  static constexpr std::array<double, points> correction{
      63887.0 / 89600.0,      -427487.0 / 725760.0, 3498217.0 / 3628800.0, -500327.0 / 403200.0, 6467.0 / 5670.0,
      -2616161.0 / 3628800.0, 24019.0 / 80640.0,    -263077.0 / 3628800.0, 8183.0 / 1036800.0};

  // Neumaier's compensated sum: state[at] the sum, state[at + 1] its rounding errors.
  static void add(std::span<double> state, std::size_t at, double x) {
    const double sum = state[at] + x;
    state[at + 1] += std::abs(state[at]) >= std::abs(x) ? (state[at] - sum) + x : (x - sum) + state[at];
    state[at] = sum;
  }

  // sum_{j=0..n} w_j f_j / h by Gregory's rule (n >= points - 1): the compensated sum of every f_j, less the end
  // corrections from the first and the last `points` values.
  static double gregory(std::span<const double> state, std::size_t sum, std::size_t first, std::size_t ring,
                        std::size_t n) {
    double corrections = 0.0;
    for (std::size_t j = 0; j < points; ++j)
      corrections += correction[j] * (state[first + j] + state[ring + (n - j) % points]);
    return (state[sum] + state[sum + 1]) - corrections;
  }

  // w[j][i]: int_0^j l_i(x) dx, the Lagrange basis l_i of the points 0 .. m (x in steps), for j, m < points.
  struct Weights {
    std::array<std::array<std::array<double, points>, points>, points> w{};  // [m][j][i]
  };
  static const Weights& weights() {
    static const Weights table = [] {
      Weights t;
      for (std::size_t m = 1; m < points; ++m)
        for (std::size_t i = 0; i <= m; ++i) {
          // l_i's monomial coefficients, exactly: prod_{k != i} (x - k) / (i - k), integers over one denominator.
          std::array<long double, points + 1> c{};
          c[0] = 1.0L;
          long double denominator = 1.0L;
          std::size_t degree = 0;
          for (std::size_t k = 0; k <= m; ++k) {
            if (k == i) continue;
            for (std::size_t d = degree + 1; d > 0; --d) c[d] = c[d - 1] - static_cast<long double>(k) * c[d];
            c[0] = -static_cast<long double>(k) * c[0];
            ++degree;
            denominator *= static_cast<long double>(i) - static_cast<long double>(k);
          }
          for (std::size_t j = 1; j <= m; ++j) {
            long double integral = 0.0L, power = static_cast<long double>(j);
            for (std::size_t d = 0; d <= degree; ++d, power *= static_cast<long double>(j))
              integral += c[d] * power / static_cast<long double>(d + 1);
            t.w[m][j][i] = static_cast<double>(integral / denominator);
          }
        }
      return t;
    }();
    return table;
  }

  // I1(t_j) / h by the polynomial through L_0 .. L_m.
  static double start_integral(std::span<const double> state, std::size_t m, std::size_t j) {
    double sum = 0.0;
    for (std::size_t i = 0; i <= m; ++i) sum += weights().w[m][j][i] * state[first_l + i];
    return sum;
  }

  // Before step points - 1: I1 and I2 from the polynomials through the steps so far (n + 1 points).
  static void early(std::span<double> state, std::size_t n) {
    const double h = state[step];
    std::array<double, points> g{};
    for (std::size_t j = 1; j <= n; ++j) g[j] = start_integral(state, n, j) / static_cast<double>(j);  // I1 / t
    state[i1] = h * start_integral(state, n, n);
    double i2_over_h = 0.0;
    for (std::size_t i = 0; i <= n; ++i) i2_over_h += weights().w[n][n][i] * g[i];
    state[i2] = h * i2_over_h;
  }

  // At step points - 1: I1(t_j) / t_j of the first steps from the polynomial through all their L, for good.
  static void finish_start(std::span<double> state) {
    for (std::size_t j = 0; j < points; ++j) {
      const double g = j == 0 ? 0.0 : start_integral(state, points - 1, j) / static_cast<double>(j);
      state[first_g + j] = g;
      state[ring_g + j] = g;
      add(state, sum_g, g);
    }
  }
};

}  // namespace nonsep
