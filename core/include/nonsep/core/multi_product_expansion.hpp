#pragma once
// Multi-product expansion (MPE), eqs. (mpe43) and (mpe63) of Chin's paper, with any number of terms m:
//
//   T^MPE(dt) = sum_{i=1..m} c_i T^{k_i}(dt / k_i),   k_i = i,   c_i = prod_{j != i} k_i^n / (k_i^n - k_j^n),
//
// n = 2/3. The basic step's error is a series in dt^(2/3) (eq. torder), and the c_i (which sum to 1) cancel its
// first m-1 terms, so the order is 2m/3. Each term T^k(dt/k) starts from the same state; their results are
// combined linearly, which is why MPE is neither symplectic nor exactly time-reversible (the paper: "no longer
// symplectic, but is like Runge-Kutta-Nystrom type algorithms").
//
// Cost: m(m+1)/2 basic steps per step. The first-same-as-last gradient at the starting point is evaluated once
// and shared by all terms; the combined point is new, so each MPE step costs one extra gradient evaluation.
#include <cmath>
#include <cstdint>
#include <vector>

#include "nonsep/core/chin_basic_step.hpp"

namespace nonsep {

template <class Base = ChinBasicStep>
class MultiProductExpansion {
 public:
  static constexpr int max_terms = 16;

  // Throws InvalidArgument when terms is outside [1, max_terms].
  MultiProductExpansion(Base base, int terms) : base_(std::move(base)), weights_(weights_for(terms)) {}
  // The expansion of the requested order (2/3, 4/3, 2, 8/3, ...); throws InvalidArgument listing valid orders.
  static MultiProductExpansion for_order(Base base, const Fraction& order) {
    return MultiProductExpansion(std::move(base), chin_order_index(order, max_terms, "mpe"));
  }

  // c_i of the m-term expansion, i = 1..m (index i-1).
  static std::vector<double> weights_for(int terms) {
    if (terms < 1 || terms > max_terms)
      throw InvalidArgument("mpe terms must be between 1 and " + std::to_string(max_terms) + " (found " +
                            std::to_string(terms) + ")");
    std::vector<double> c(static_cast<std::size_t>(terms), 1.0);
    for (int i = 1; i <= terms; ++i) {
      const double ki = std::pow(static_cast<double>(i), 2.0 / 3.0);
      for (int j = 1; j <= terms; ++j)
        if (j != i) c[static_cast<std::size_t>(i - 1)] *= ki / (ki - std::pow(static_cast<double>(j), 2.0 / 3.0));
    }
    return c;
  }

  int terms() const { return static_cast<int>(weights_.size()); }
  const std::vector<double>& weights() const { return weights_; }
  Fraction order() const { return Fraction(2 * terms(), 3); }
  const Base& base() const { return base_; }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  IntegratorDescription describe() const {
    IntegratorDescription d = base_.describe();
    d.scheme = "mpe";
    d.order = order();
    d.symplectic = false;
    d.time_reversible = false;
    const auto m = static_cast<std::uint64_t>(terms());
    d.basic_steps_per_step *= m * (m + 1) / 2;
    return d;
  }

  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    const int m = terms();
    if (m == 1) {
      base_.step(model, x, dt);
      return;
    }
    start_ = x;
    base_.prime(model, start_);
    const auto start_cache = base_.save_cache();
    // Terms run from k = m down to 1; the result is accumulated as y_m + sum_k c_k (y_k - y_m), which equals
    // sum_k c_k y_k because the c_k sum to 1 and loses less to rounding when the y_k are close.
    for (int k = m; k >= 1; --k) {
      term_ = start_;
      if (k != m) base_.restore_cache(start_cache);
      for (int r = 0; r < k; ++r) base_.step(model, term_, dt / k);
      if (k == m) {
        last_ = term_;
        x = term_;
        continue;
      }
      const double c = weights_[static_cast<std::size_t>(k - 1)];
      accumulate(x.q(), c, term_.q(), last_.q());
      accumulate(x.p(), c, term_.p(), last_.p());
    }
  }
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) { base_.prime(model, x); }
  using Cache = typename Base::Cache;
  Cache save_cache() const { return base_.save_cache(); }
  void restore_cache(const Cache& cache) { base_.restore_cache(cache); }

 private:
  static void accumulate(std::span<double> sum, double c, std::span<const double> y, std::span<const double> ym) {
    for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += c * (y[i] - ym[i]);
  }

  Base base_;
  std::vector<double> weights_;
  PhaseSpaceBatch start_, term_, last_;  // the starting point, the term being run, and y_m
};

}  // namespace nonsep
