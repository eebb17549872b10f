#pragma once
// The steps of a multi-product expansion, eqs. (mpe43) and (mpe63) of Chin's paper, over chin_stages: what
// MultiProductExpansion (multi_product_expansion.hpp) computes, for a stepping kernel that takes whole MPE steps of a
// block of states with the model's gradients inlined (chin_kernel.hpp).
//
//   T^MPE(dt) = sum_{k=1..m} c_k T^k(dt / k)
//
// Each step: term k = m, m-1, ..., 1 takes k basic steps of eps_k = cbrt(dt / k) from the step's start, the outer
// gradient at the start shared by all terms; the result is y_m + sum_{k<m} c_k (y_k - y_m) (mpe_accumulate, the rule
// MultiProductExpansion uses), accumulated in that order; the next step starts from the outer gradient at the combined
// point, evaluated anew. The terms are independent, so every number sees the operations of MultiProductExpansion's
// batched step in the same order, and a kernel compiled with the evaluation path's flags gives its numbers bit for bit
// (tests/core/test_chin_kernel.cpp).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "nonsep/core/kernel/chin_stages.hpp"

namespace nonsep {

// sum += c (y - ym), number by number: one term's share of the expansion (StaticSize as for chin_stages).
template <std::size_t StaticSize = 0>
inline void mpe_accumulate(std::span<double> sum, double c, std::span<const double> y, std::span<const double> ym) {
  const std::size_t size = StaticSize > 0 ? StaticSize : sum.size();
  for (std::size_t i = 0; i < size; ++i) sum[i] += c * (y[i] - ym[i]);
}

// Scratch numbers chin_expansion_stages needs for states of `size` numbers of q: eight arrays (the step's start q, p
// and outer gradient; y_m's q and p; a term's q, p and outer gradient).
constexpr std::size_t chin_expansion_scratch(std::size_t size) { return 8 * size; }

// The call's steps, each an expansion of call.weights.size() >= 2 terms (ChinStepsCall, chin_stages.hpp: eps[k-1]
// = cbrt(dt / k), substeps 1), in place in call.q and call.p. outer_gradient: in, at the current point; out,
// unspecified (not the combined point's: the caller evaluates that anew). Evaluations per state: m (m + 1) / 2 basic
// steps' (4 grad T, 4 grad V each) per step, and one outer gradient between steps (call.steps - 1).
// `scratch`: chin_expansion_scratch(call.q.size()) numbers. A model exception propagates, leaving the arrays
// unspecified.
template <std::size_t StaticSize = 0, Model M>
inline void chin_expansion_stages(const M& model, const ChinStepsCall& call, std::span<double> scratch) {
  if (call.steps == 0) return;  // a call of no steps: the kernel's block evaluated its outer gradient
  const std::size_t size = StaticSize > 0 ? StaticSize : call.q.size();
  const auto array = [&](std::size_t i) { return scratch.subspan(i * size, size); };
  const std::span<double> start_q = array(0), start_p = array(1), start_gradient = array(2), last_q = array(3),
                          last_p = array(4), term_q = array(5), term_p = array(6), term_gradient = array(7);
  const auto copy = [&](std::span<const double> from, std::span<double> to) {
    std::copy_n(from.begin(), size, to.begin());
  };
  const std::size_t m = call.weights.size();
  const bool ttv = call.form == HamiltonianForm::TTV;
  const auto term = [&](std::size_t k, std::span<double> q, std::span<double> p, std::span<double> gradient) {
    chin_stages<StaticSize>(model, call.form, call.coefficients, call.eps.subspan(k - 1, 1), k, call.count, q, p,
                            gradient, call.inner_gradient);
  };
  for (std::uint64_t step = 0; step < call.steps; ++step) {
    copy(call.q, start_q);
    copy(call.p, start_p);
    copy(call.outer_gradient, start_gradient);
    term(m, call.q, call.p, call.outer_gradient);  // y_m, in the call's arrays, where the sum accumulates
    copy(call.q, last_q);
    copy(call.p, last_p);
    for (std::size_t k = m - 1; k >= 1; --k) {
      // Term 1, the last, runs in the start's arrays; the others in copies of them.
      const bool last = k == 1;
      if (!last) {
        copy(start_q, term_q);
        copy(start_p, term_p);
        copy(start_gradient, term_gradient);
      }
      const std::span<double> q = last ? start_q : term_q, p = last ? start_p : term_p;
      term(k, q, p, last ? start_gradient : term_gradient);
      mpe_accumulate<StaticSize>(call.q, call.weights[k - 1], q, last_q);
      mpe_accumulate<StaticSize>(call.p, call.weights[k - 1], p, last_p);
    }
    if (step + 1 < call.steps) chin_gradient(model, ttv, ttv ? call.q : call.p, call.outer_gradient, call.count);
  }
}

}  // namespace nonsep
