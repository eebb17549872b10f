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
//
// Batching: step() runs the m terms side by side as one batch of m x count states, term k with step size dt/k
// (ChinBasicStep's per-state step): round r advances every term with k > r by one basic step, so a step crosses
// into the model 8m times instead of 4m(m+1) (one call per stage for all terms). step_term_by_term() runs the
// terms one after the other; both give the same numbers and evaluation counts bit for bit (tests/core).
//
// The base stepper must be a StepperWithPerStateStepSizes (below), and the weights assume that its error is the
// basic step's series in dt^(2/3) (eq. torder). ChinBasicStep is such a stepper. TripletComposition is not (its
// step takes one dt for the whole batch), so MultiProductExpansion<TripletComposition<>> is refused at compile
// time with that concept named.
#include <algorithm>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <span>
#include <vector>

#include "nonsep/core/kernel/chin_expansion_stages.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

namespace detail {
// A model type for checking steppers' member templates in concepts; declared only, never evaluated.
struct ModelArchetype {
  std::size_t dimension() const;
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const;
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const;
};
}  // namespace detail

// What MultiProductExpansion needs of its base stepper B (b a B, cb a const B, model a Model, x a PhaseSpaceBatch):
//   b.step(model, x, dt)           advances every state of x by one double dt
//   b.step(model, x, sizes)        advances state i of x by sizes[i] (std::span<const double>, x.count() entries)
//   b.prime(model, x)              makes the first-same-as-last gradient at x's point available
//   typename B::Cache, cb.save_cache(cache), b.restore_cache(cache)    that gradient saved (into cache, reusing its
//                                  storage) and restored
//   b.keep_cache_prefix(size)      that gradient kept for the batch's first `size` numbers of q and p only
//   cb.evaluations()               EvaluationCounts, per state
//   cb.describe()                  IntegratorDescription
template <class B>
concept StepperWithPerStateStepSizes = requires(B& b, const B& cb, const detail::ModelArchetype& model,
                                                PhaseSpaceBatch& x, double dt, std::span<const double> sizes,
                                                typename B::Cache& cache) {
  b.step(model, x, dt);
  b.step(model, x, sizes);
  b.prime(model, x);
  cb.save_cache(cache);
  b.restore_cache(cache);
  b.keep_cache_prefix(std::size_t{});
  { cb.evaluations() } -> std::convertible_to<const EvaluationCounts&>;
  { cb.describe() } -> std::convertible_to<IntegratorDescription>;
};

template <StepperWithPerStateStepSizes Base = ChinBasicStep>
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
  Fraction order() const { return description({}, terms()).order; }
  const Base& base() const { return base_; }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  IntegratorDescription describe() const { return description(base_.describe(), terms()); }
  // The description of the expansion of `terms` terms over a base step described by `base` (its scheme's,
  // chin_schemes.hpp, without building one).
  static IntegratorDescription description(IntegratorDescription base, int terms) {
    base.scheme = "mpe";
    base.order = Fraction(2 * terms, 3);
    base.symplectic = false;
    base.time_reversible = false;
    const auto m = static_cast<std::uint64_t>(terms);
    base.basic_steps_per_step *= m * (m + 1) / 2;
    return base;
  }

  // Advances every state of `x` by dt, the terms batched (above).
  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    const int m = terms();
    if (m == 1) {
      base_.step(model, x, dt);
      return;
    }
    const std::size_t count = x.count(), n = x.dimension(), size = count * n;
    base_.prime(model, x);
    base_.save_cache(start_cache_);
    // Group g = m - k holds term k: states [g count, (g + 1) count), step size dt / k. The groups still running
    // are a prefix, because the term with the fewest steps (the smallest k) is the last group: after each round the
    // last running group is done, is copied to done_ and dropped from terms_ and from the base's cache.
    if (terms_.dimension() != n) terms_ = PhaseSpaceBatch(n, 0);
    if (done_.dimension() != n) done_ = PhaseSpaceBatch(n, 0);
    terms_.resize(static_cast<std::size_t>(m) * count);
    done_.resize(static_cast<std::size_t>(m) * count);
    step_sizes_.resize(static_cast<std::size_t>(m) * count);
    cache_.at.clear();
    cache_.gradient.clear();
    for (int g = 0; g < m; ++g) {
      const auto offset = static_cast<std::ptrdiff_t>(static_cast<std::size_t>(g) * size);
      std::copy(x.q().begin(), x.q().end(), terms_.q().begin() + offset);
      std::copy(x.p().begin(), x.p().end(), terms_.p().begin() + offset);
      std::fill_n(step_sizes_.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(g) * count), count,
                  dt / (m - g));
      cache_.at.insert(cache_.at.end(), start_cache_.at.begin(), start_cache_.at.end());
      cache_.gradient.insert(cache_.gradient.end(), start_cache_.gradient.begin(), start_cache_.gradient.end());
    }
    base_.restore_cache(cache_);
    for (int round = 0; round < m; ++round) {
      const auto running = static_cast<std::size_t>(m - round);  // the terms with k > round
      base_.step(model, terms_, std::span<const double>(step_sizes_).first(running * count));
      if (round == 0) {
        base_.save_cache(last_term_cache_);  // left by term 1, which step_term_by_term runs last
        last_term_cache_.at.erase(last_term_cache_.at.begin(),
                                  last_term_cache_.at.end() - static_cast<std::ptrdiff_t>(size));
        last_term_cache_.gradient.erase(last_term_cache_.gradient.begin(),
                                        last_term_cache_.gradient.end() - static_cast<std::ptrdiff_t>(size));
      }
      const std::size_t finished = (running - 1) * size;  // where term k = round + 1 starts
      std::copy_n(terms_.q().begin() + static_cast<std::ptrdiff_t>(finished), size,
                  done_.q().begin() + static_cast<std::ptrdiff_t>(finished));
      std::copy_n(terms_.p().begin() + static_cast<std::ptrdiff_t>(finished), size,
                  done_.p().begin() + static_cast<std::ptrdiff_t>(finished));
      terms_.resize((running - 1) * count);
      base_.keep_cache_prefix(finished);
    }
    base_.restore_cache(last_term_cache_);
    // y_m, then + c_k (y_k - y_m) for k = m-1 down to 1, as step_term_by_term accumulates.
    std::copy_n(done_.q().begin(), size, x.q().begin());
    std::copy_n(done_.p().begin(), size, x.p().begin());
    const std::span<const double> q = done_.q(), p = done_.p();
    for (int k = m - 1; k >= 1; --k) {
      const double c = weights_[static_cast<std::size_t>(k - 1)];
      const std::size_t offset = static_cast<std::size_t>(m - k) * size;
      mpe_accumulate(x.q(), c, q.subspan(offset, size), q.first(size));
      mpe_accumulate(x.p(), c, p.subspan(offset, size), p.first(size));
    }
  }

  // n steps of dt: bit for bit n calls of step(model, x, dt), evaluations counted alike. A base that takes whole
  // expansions to a model's kernel (step_expansion_n: ChinBasicStep, SeparableComposition without a separable part)
  // gets the n steps in one call (chin_expansion_stages.hpp); otherwise the steps are taken one by one.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if constexpr (requires { base_.step_expansion_n(model, x, dt, std::span<const double>(weights_), n); })
      if (terms() > 1 && base_.step_expansion_n(model, x, dt, std::span<const double>(weights_), n)) return;
    for (std::uint64_t k = 0; k < n; ++k) step(model, x, dt);
  }

  // The same step, one term after the other (the reference step() is tested against).
  template <Model M>
  void step_term_by_term(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    const int m = terms();
    if (m == 1) {
      base_.step(model, x, dt);
      return;
    }
    start_ = x;
    base_.prime(model, start_);
    base_.save_cache(start_cache_);
    // Terms run from k = m down to 1; the result is accumulated as y_m + sum_k c_k (y_k - y_m), which equals
    // sum_k c_k y_k because the c_k sum to 1 and loses less to rounding when the y_k are close.
    for (int k = m; k >= 1; --k) {
      term_ = start_;
      if (k != m) base_.restore_cache(start_cache_);
      for (int r = 0; r < k; ++r) base_.step(model, term_, dt / k);
      if (k == m) {
        last_ = term_;
        x = term_;
        continue;
      }
      const double c = weights_[static_cast<std::size_t>(k - 1)];
      mpe_accumulate(x.q(), c, term_.q(), last_.q());
      mpe_accumulate(x.p(), c, term_.p(), last_.p());
    }
  }
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) {
    base_.prime(model, x);
  }

 private:
  Base base_;
  std::vector<double> weights_;
  PhaseSpaceBatch start_, term_, last_;  // step_term_by_term: the starting point, the term being run, and y_m
  PhaseSpaceBatch terms_, done_;         // step: the terms still running side by side, and every term's end point
  std::vector<double> step_sizes_;       // step: dt / k per state of terms_
  typename Base::Cache start_cache_, cache_, last_term_cache_;  // the first-same-as-last gradients saved: at the
                                                                // start, once per term (step), and term 1's
};

}  // namespace nonsep
