#pragma once
// The basic step of H = H_TTV + K(p) + U(q) (or H_VVT + K + U): Chin's basic step, eq. (expalg), composed
// symmetrically with the exact flows of the separable part. The paper closes with the principle behind it: any
// Hamiltonian that the error terms of an explicit splitting can model is solved by that splitting; adding a
// separable K(p) + U(q), whose flows are exact, keeps the step explicit, symplectic and time-reversible.
//
//   Phi(dt) = S(dt/2) T(dt) S(dt/2),     S(h) = exp(h/2 U) exp(h K) exp(h/2 U)
//
// T(dt) the basic step (chin_basic_step.hpp), and the exact flows
//   exp(h K): q <- q + h grad K(p)          exp(h U): p <- p - h grad U(q).
// A model with only U (K = 0) takes S(h) = exp(h U), with only K S(h) = exp(h K); a model with neither is stepped
// by the basic step alone, bit for bit.
//
// Derivation (Lie operators as in the paper, eps = cbrt(dt), B = K^ + U^ the separable part's operator).
// The basic step is T(dt) = exp(eps^3 A + eps^5 E5 + eps^7 E7 + ...), A = [T T V] the operator of H_TTV, odd powers
// of eps only (eq. torder; the splitting is palindromic and eps -> -eps inverts it). The half-flow is Strang's
// splitting of B: S(h) = exp(h B + h^3 B3 + h^5 B5 + ...), B3 Strang's double brackets of K^ and U^, with
// h = dt/2 = eps^3/2. By the symmetric BCH formula,
//   log Phi = eps^3 (A + B) + eps^5 E5 + eps^7 E7 + eps^9 (E9 + B3/4 + (1/12)[A A B] - (1/24)[B B A]) + O(eps^11),
// and Phi(-dt) = Phi(dt)^-1 (each factor is inverted by eps -> -eps), so log Phi has odd powers of eps only.
// Hence:
//   - the leading term is eps^3 (A + B) = dt H^ with H = H_TTV + K + U: Phi solves the full H;
//   - the separable part's error enters at eps^9 = dt^3 (local), the basic step's at eps^5 = dt^(5/3): Phi has the
//     basic step's error structure, a series in odd powers of eps from eps^5 on, and its order 2/3;
//   - triplet composition (eqs. sym43, sym63, triplet_composition.hpp) with s = 2^(3/(k+3)) cancels the whole
//     eps^(k+3) coefficient whatever operator it is: the separable terms at eps^9 are cancelled by the level that
//     raises 2 to 8/3 like E9 is, and every triplet order 2j/3 holds for Phi;
//   - Phi^k(dt/k) = exp(sum_j dt^(j/3) k^(1 - j/3) C_j), j odd: every error term carries a power k^(-2i/3), the
//     dt^3 separable term k^(-2) = k^(-6/3) among them, so the multi-product expansion's weights (mpe43, mpe63,
//     n = 2/3) cancel them as they cancel E5, E7, E9, and every MPE order 2m/3 holds for Phi.
// No order is lost and no higher-order separable splitting (Yoshida, Suzuki) is needed: a second-order symmetric
// S(h) already puts the separable error at eps^9, where the basic step has its own E9 term; a better S(h) would only
// change the constant of that term. The measured orders on the Mathews-Lakshmanan oscillator and a 2D model with
// K and U are in tests/core/test_separable_convergence.cpp.
//
// Cost per step: with K and U, 2 grad K and 4 grad U evaluations besides the basic step's; U alone, 2 grad U;
// K alone, 2 grad K. The basic step's first-same-as-last gradient survives the half-flows when they leave its inner
// variable unchanged (TTV: no K, so q is not moved; VVT: no U); otherwise the basic step evaluates it again.
//
// SeparableComposition wraps a base stepper with the ChinBasicStep interface (step with one dt or one per state,
// step_n, step_schedule_n, step_expansion_n, prime, save_cache, restore_cache, keep_cache_prefix, evaluations,
// describe, form, coefficients); it is the base of the catalogue's triplet and MPE (scheme_catalogue.hpp). Errors:
// those of the base step; the model's exceptions propagate and leave x unspecified but valid.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

// One exact flow of the separable part: a drift by grad K (kick false) or a kick by grad U (kick true), over
// fraction * dt.
struct SeparableFlow {
  bool kick;
  double fraction;
};

template <class Base = ChinBasicStep>
class SeparableComposition {
 public:
  using Cache = typename Base::Cache;

  explicit SeparableComposition(Base base = Base()) : base_(std::move(base)) {}

  const Base& base() const { return base_; }
  HamiltonianForm form() const { return base_.form(); }
  const ChinCoefficients& coefficients() const { return base_.coefficients(); }
  IntegratorDescription describe() const { return base_.describe(); }
  // The base step's evaluations plus grad_K and grad_U of the separable flows.
  const EvaluationCounts& evaluations() const {
    total_ = base_.evaluations();
    total_.grad_K = separable_.grad_K;
    total_.grad_U = separable_.grad_U;
    return total_;
  }

  // The flows of one step of dt in order, the basic step among them: calls separable(SeparableFlow) for each exact
  // flow and basic() for the basic step. The schedule shared with the tangent map (tangent_separable_composition.hpp).
  template <class Separable, class Basic>
  static void for_each_flow(bool k, bool u, Separable&& separable, Basic&& basic) {
    auto half = [&] {
      if (k && u) {
        separable(SeparableFlow{true, 0.25});
        separable(SeparableFlow{false, 0.5});
        separable(SeparableFlow{true, 0.25});
      } else if (k || u) {
        separable(SeparableFlow{u, 0.5});
      }
    };
    half();
    basic();
    half();
  }

  // Advances every state of x by dt. Without a separable part (has_K and has_U false), exactly base.step.
  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    if (!has_separable_part(model)) {
      base_.step(model, x, dt);
      return;
    }
    check_batch_fits(model, x);
    check_step_size(dt);
    for_each_flow(
        has_K(model), has_U(model), [&](SeparableFlow f) { flow(model, x, f, std::span<const double>(&dt, 1)); },
        [&] { base_.step(model, x, dt); });
  }

  // Advances state b of x by dt[b] (MultiProductExpansion's batched terms); errors as ChinBasicStep's.
  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, std::span<const double> dt) {
    if (!has_separable_part(model)) {
      base_.step(model, x, dt);
      return;
    }
    check_batch_fits(model, x);
    if (dt.size() != x.count())
      throw InvalidArgument("a batch of " + std::to_string(x.count()) + " states needs as many step sizes (found " +
                            std::to_string(dt.size()) + ")");
    for (double h : dt) check_step_size(h);
    for_each_flow(
        has_K(model), has_U(model), [&](SeparableFlow f) { flow(model, x, f, dt); }, [&] { base_.step(model, x, dt); });
  }

  // n steps of dt, bit for bit n calls of step(); without a separable part the base's step_n.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if (!has_separable_part(model)) {
      base_.step_n(model, x, dt, n);
      return;
    }
    for (std::uint64_t s = 0; s < n; ++s) step(model, x, dt);
  }

  // n times the schedule dts of steps, bit for bit the steps one by one; without a separable part the base's
  // step_schedule_n (one kernel call for the whole run when the model has a kernel).
  template <Model M>
  void step_schedule_n(const M& model, PhaseSpaceBatch& x, std::span<const double> dts, std::uint64_t n) {
    if (!has_separable_part(model)) {
      base_.step_schedule_n(model, x, dts, n);
      return;
    }
    for (std::uint64_t s = 0; s < n; ++s)
      for (double dt : dts) step(model, x, dt);
  }

  // n steps of the multi-product expansion with `weights` in one kernel call (ChinBasicStep::step_expansion_n):
  // without a separable part the base's; with one, false (the expansion's terms compose the separable flows, which
  // the kernel does not take).
  template <Model M>
  bool step_expansion_n(const M& model, PhaseSpaceBatch& x, double dt, std::span<const double> weights,
                        std::uint64_t n) {
    return !has_separable_part(model) && base_.step_expansion_n(model, x, dt, weights, n);
  }

  // Primes the base's first-same-as-last gradient when the first half-flow leaves its point unchanged.
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) {
    const bool moved = base_.form() == HamiltonianForm::TTV ? has_K(model) : has_U(model);
    if (!moved) base_.prime(model, x);
  }
  void save_cache(Cache& cache) const { base_.save_cache(cache); }
  void restore_cache(const Cache& cache) { base_.restore_cache(cache); }
  void keep_cache_prefix(std::size_t size) { base_.keep_cache_prefix(size); }

  // The flow's update of `changed` (p for a kick, q for a drift) from the gradient at the unchanged variable:
  // changed_b += (-1 for a kick, +1 for a drift) f.fraction dt_b gradient_b, dt one for all states or one per state.
  static void shift(std::span<double> changed, std::span<const double> gradient, SeparableFlow f,
                    std::span<const double> dt, std::size_t count, std::size_t n) {
    const double sign = f.kick ? -1.0 : 1.0;
    for (std::size_t b = 0; b < count; ++b) {
      const double h = sign * f.fraction * dt[dt.size() == 1 ? 0 : b];
      for (std::size_t i = b * n; i < (b + 1) * n; ++i) changed[i] += h * gradient[i];
    }
  }

 private:
  // One exact flow of every state, over f.fraction * dt (dt one for all states or one per state).
  template <Model M>
  void flow(const M& model, PhaseSpaceBatch& x, SeparableFlow f, std::span<const double> dt) {
    if constexpr (ModelWithSeparablePart<M>) {
      const std::size_t count = x.count(), n = x.dimension();
      gradient_.resize(x.size());
      std::span<double> changed = f.kick ? x.p() : x.q();
      if (f.kick) {
        model.grad_U(std::as_const(x).q(), std::span<double>(gradient_), count);
        separable_.grad_U += count;
      } else {
        model.grad_K(std::as_const(x).p(), std::span<double>(gradient_), count);
        separable_.grad_K += count;
      }
      shift(changed, gradient_, f, dt, count, n);
    }
  }

  Base base_;
  EvaluationCounts separable_;
  mutable EvaluationCounts total_;
  std::vector<double> gradient_;
};

// The basic step of the catalogue: Chin's basic step with the separable part's flows around it when the model has one.
using SeparableBasicStep = SeparableComposition<ChinBasicStep>;

}  // namespace nonsep
