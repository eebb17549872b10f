#pragma once
// A stepping kernel: the steps of a ChinStepsCall (chin_stages.hpp) with the model's gradients inlined, as the
// plugin SDK instantiates it inside each plugin (one kernel per model, compiled with the model). The flows are
// chin_stages' own; what differs from the evaluation path (ChinBasicStep with a plugin's batched gradients) is only
// the order in which states and steps are visited:
//   - the states go in blocks that take all of the call's steps before the next block starts, so a block stays in
//     the first-level cache (or in registers) instead of the whole batch streaming through memory 17 times a step;
//   - for a dimension N known at compile time (FixedDimension = N > 0), blocks of B = block_states(N) states are
//     copied into local arrays whose sizes the compiler knows, so that the nine flows and the gradients vectorize
//     across the block without alias checks or loops of unknown length;
//   - the states left over after the whole blocks go in place, as one block of the caller's arrays; up to three
//     left over (a single trajectory, the rounds of a multi-product expansion's terms) go in local arrays of two
//     states and of one, which keep q, p and both gradients in registers through the nine flows (dimension <= 4),
//     a pair's two chains interleaved;
//   - with a dimension known only at run time (FixedDimension = 0), blocks of the caller's arrays.
// Why blocks of 32 states (docs/performance.md, "Stepping kernels"): one state's step is a chain of dependent
// operations (a division in each grad V; about 55 ns a step in registers, twice that through memory), so a block must
// hold enough independent states to keep the divider and the multipliers busy. Blocks of 16 ran at the chain's
// latency whatever the vector width (GCC unrolls their loops completely and vectorizes them piecemeal); blocks of 32
// and 64 run at the machine's throughput, as the hand-written loop over all states does.
// A call with weights takes whole steps of a multi-product expansion (chin_expansion_stages.hpp) over the same blocks,
// its terms one after the other, so that one trajectory's expansion stays in registers.
// A tangent call (chin_tangent_kernel_blocks) takes the steps with k tangent vectors per state
// (chin_tangent_stages.hpp) over the same blocks, the vectors in local arrays beside the states while a block's
// tangents take at most 1024 numbers of each array, else in the caller's arrays. Each number sees the same operations
// in the same order as in the evaluation path, so a kernel compiled with the evaluation path's flags gives its numbers
// bit for bit (tests/core/test_chin_kernel.cpp, tests/core/test_chin_tangent_kernel.cpp).
//
// Throws what the model throws; the call's arrays then hold a mixture of steps (the caller redoes the call through
// the evaluation path).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "nonsep/core/kernel/chin_expansion_stages.hpp"
#include "nonsep/core/kernel/chin_stages.hpp"
#include "nonsep/core/kernel/chin_tangent_stages.hpp"

namespace nonsep {

// The version of what a kernel computes (the ChinStepsCall it takes, chin_stages' flows). A plugin of ABI version 5
// has the kernels of this version (plugin_abi.h: the ABI version says it); a plugin of ABI version 4 named its
// kernel version in its metadata, and the host steps those whose version is not this one through their evaluations.
// Version 2: a call carries a schedule of sub-steps (ChinStepsCall::substeps). Version 3: a call may carry a
// multi-product expansion's weights (ChinStepsCall::weights). Version 4 (ABI version 5): a call of no steps evaluates
// the outer gradient at the call's point (ChinStepsCall::steps), and the tangent kernel (chin_tangent_kernel_blocks)
// is part of the same version.
inline constexpr std::uint64_t chin_kernel_version = 4;

// States per block of local arrays for a fixed dimension: 32 states, at most 128 numbers of each array (the four
// arrays then take 4 KB of the first-level cache), one state from dimension 128 on.
constexpr std::size_t block_states(std::size_t dimension) { return std::clamp<std::size_t>(128 / dimension, 1, 32); }
// States per block of the caller's arrays when the dimension is known at run time only: about 512 numbers each.
inline std::size_t block_states_at_run_time(std::size_t dimension) { return std::max<std::size_t>(1, 512 / dimension); }

namespace detail {

// Whether the call's eps holds one entry per state (else one per sub-step or term, for every state).
inline bool eps_per_state(const ChinStepsCall& call) {
  return call.weights.empty() && call.substeps == 1 && call.eps.size() != 1;
}

// A call of no steps (chin_outer_gradient) for states [first, first + B) of dimension N: the outer gradient in local
// arrays of its own, with the code the steps' blocks evaluate it with (so the same numbers). The blocks below branch
// here before they form their arrays: evaluated on those arrays, the branch kept them out of registers (paper1d's
// basic step took 1.45x the time, bench/compare_builds.py).
template <std::size_t N, std::size_t B, Model M>
inline void chin_outer_gradient_in_local_arrays(const M& model, const ChinStepsCall& call, std::size_t first) {
  constexpr std::size_t size = B * N;
  std::array<double, size> point, gradient;
  const bool ttv = call.form == HamiltonianForm::TTV;
  const auto offset = static_cast<std::ptrdiff_t>(first * N);
  std::copy_n((ttv ? call.q : call.p).begin() + offset, size, point.begin());
  chin_gradient(model, ttv, point, gradient, B);
  std::copy_n(gradient.begin(), size, call.outer_gradient.begin() + offset);
}

// The call's steps for states [first, first + B) of dimension N, in local arrays; Expansion: call.weights is not
// empty (a separate instantiation, so that the basic steps' code is not shaped by the expansion's).
template <std::size_t N, std::size_t B, bool Expansion, Model M>
inline void chin_steps_in_local_arrays(const M& model, const ChinStepsCall& call, std::size_t first) {
  if (call.steps == 0) return chin_outer_gradient_in_local_arrays<N, B>(model, call, first);
  constexpr std::size_t size = B * N;
  std::array<double, size> q, p, outer_gradient, inner_gradient;
  std::array<double, B> eps;
  const std::size_t offset = first * N;
  std::copy_n(call.q.begin() + static_cast<std::ptrdiff_t>(offset), size, q.begin());
  std::copy_n(call.p.begin() + static_cast<std::ptrdiff_t>(offset), size, p.begin());
  std::copy_n(call.outer_gradient.begin() + static_cast<std::ptrdiff_t>(offset), size, outer_gradient.begin());
  std::span<const double> block_eps = call.eps;
  if (eps_per_state(call)) {
    std::copy_n(call.eps.begin() + static_cast<std::ptrdiff_t>(first), B, eps.begin());
    block_eps = eps;
  }
  const ChinStepsCall block{call.form, call.coefficients, block_eps,      call.substeps, call.steps, B, q,
                            p,         outer_gradient,    inner_gradient, call.weights};
  if constexpr (!Expansion) {
    chin_scheduled_steps<size>(model, block);
  } else if constexpr (size <= 128) {  // the expansion's scratch on the stack too (8 KB at most)
    std::array<double, chin_expansion_scratch(size)> scratch;
    chin_expansion_stages<size>(model, block, scratch);
  } else {
    std::vector<double> scratch(chin_expansion_scratch(size));
    chin_expansion_stages<size>(model, block, scratch);
  }
  std::copy_n(q.begin(), size, call.q.begin() + static_cast<std::ptrdiff_t>(offset));
  std::copy_n(p.begin(), size, call.p.begin() + static_cast<std::ptrdiff_t>(offset));
  std::copy_n(outer_gradient.begin(), size, call.outer_gradient.begin() + static_cast<std::ptrdiff_t>(offset));
}

// The call's steps for states [first, first + states) of dimension n, in the caller's arrays.
template <bool Expansion, Model M>
inline void chin_steps_in_place(const M& model, const ChinStepsCall& call, std::size_t n, std::size_t first,
                                std::size_t states) {
  const std::size_t offset = first * n, size = states * n;
  const std::span<const double> eps = eps_per_state(call) ? call.eps.subspan(first, states) : call.eps;
  const ChinStepsCall part{call.form,
                           call.coefficients,
                           eps,
                           call.substeps,
                           call.steps,
                           states,
                           call.q.subspan(offset, size),
                           call.p.subspan(offset, size),
                           call.outer_gradient.subspan(offset, size),
                           call.inner_gradient.subspan(offset, size),
                           call.weights};
  if (chin_outer_gradient(model, part)) return;  // a call of no steps
  if constexpr (!Expansion) {
    chin_scheduled_steps(model, part);
  } else {
    std::vector<double> scratch(chin_expansion_scratch(size));
    chin_expansion_stages(model, part, scratch);
  }
}

// A tangent call's steps for states [first, first + B) of dimension N in local arrays (the tangent vectors too).
template <std::size_t N, std::size_t B, Model M>
inline void chin_tangent_steps_in_local_arrays(const M& model, const ChinTangentStepsCall& call, std::size_t first) {
  if (call.steps.steps == 0) return chin_outer_gradient_in_local_arrays<N, B>(model, call.steps, first);
  constexpr std::size_t size = B * N, capacity = size * 2 * N;  // k <= 2n vectors per state
  const std::size_t k = call.vectors, tangent_size = size * k;
  std::array<double, size> q, p, outer_gradient, inner_gradient;
  std::array<double, capacity> tangent_q, tangent_p, products, points;
  std::array<double, B> eps;
  const ChinStepsCall& c = call.steps;
  const auto offset = static_cast<std::ptrdiff_t>(first * N);
  const auto tangent_offset = static_cast<std::ptrdiff_t>(first * k * N);
  std::copy_n(c.q.begin() + offset, size, q.begin());
  std::copy_n(c.p.begin() + offset, size, p.begin());
  std::copy_n(c.outer_gradient.begin() + offset, size, outer_gradient.begin());
  std::copy_n(call.tangent_q.begin() + tangent_offset, tangent_size, tangent_q.begin());
  std::copy_n(call.tangent_p.begin() + tangent_offset, tangent_size, tangent_p.begin());
  std::span<const double> block_eps = c.eps;
  if (eps_per_state(c)) {
    std::copy_n(c.eps.begin() + static_cast<std::ptrdiff_t>(first), B, eps.begin());
    block_eps = eps;
  }
  const ChinTangentStepsCall block{
      {c.form, c.coefficients, block_eps, c.substeps, c.steps, B, q, p, outer_gradient, inner_gradient, {}},
      k,
      std::span<double>(tangent_q).first(tangent_size),
      std::span<double>(tangent_p).first(tangent_size)};
  chin_tangent_stages<size>(model, block, {products, points});
  std::copy_n(q.begin(), size, c.q.begin() + offset);
  std::copy_n(p.begin(), size, c.p.begin() + offset);
  std::copy_n(outer_gradient.begin(), size, c.outer_gradient.begin() + offset);
  std::copy_n(tangent_q.begin(), tangent_size, call.tangent_q.begin() + tangent_offset);
  std::copy_n(tangent_p.begin(), tangent_size, call.tangent_p.begin() + tangent_offset);
}

// A tangent call's steps for states [first, first + states) of dimension n in the caller's arrays; scratch holds
// 2 states*k*n numbers.
template <Model M>
inline void chin_tangent_steps_in_place(const M& model, const ChinTangentStepsCall& call, std::size_t n,
                                        std::size_t first, std::size_t states, std::span<double> scratch) {
  const ChinStepsCall& c = call.steps;
  const std::size_t k = call.vectors, offset = first * n, size = states * n, tangent_size = size * k;
  const ChinTangentStepsCall part{{c.form,
                                   c.coefficients,
                                   eps_per_state(c) ? c.eps.subspan(first, states) : c.eps,
                                   c.substeps,
                                   c.steps,
                                   states,
                                   c.q.subspan(offset, size),
                                   c.p.subspan(offset, size),
                                   c.outer_gradient.subspan(offset, size),
                                   c.inner_gradient.subspan(offset, size),
                                   {}},
                                  k,
                                  call.tangent_q.subspan(offset * k, tangent_size),
                                  call.tangent_p.subspan(offset * k, tangent_size)};
  if (chin_outer_gradient(model, part.steps)) return;  // a call of no steps
  chin_tangent_stages(model, part, {scratch.first(tangent_size), scratch.subspan(tangent_size, tangent_size)});
}

}  // namespace detail

// The steps of a tangent call (chin_tangent_stages.hpp) for `model` (its dimension is FixedDimension when that is not
// 0), over blocks of states as chin_kernel_blocks takes them; whole blocks in local arrays when a fixed dimension's
// block of tangents fits 1024 numbers, the states left over one at a time in local arrays. Requires the sizes of
// ChinTangentStepsCall and chin_eps_fit(eps.size(), substeps, count) (no weights). Allocates scratch for blocks in the
// caller's arrays (std::bad_alloc).
template <std::size_t FixedDimension, ModelWithHessianProducts M>
void chin_tangent_kernel_blocks(const M& model, const ChinTangentStepsCall& call) {
  const std::size_t count = call.steps.count, k = call.vectors;
  std::size_t first = 0;
  if constexpr (FixedDimension > 0) {
    constexpr std::size_t B = block_states(FixedDimension);
    if constexpr (B * FixedDimension * 2 * FixedDimension <= 1024) {
      for (; first + B <= count; first += B)
        detail::chin_tangent_steps_in_local_arrays<FixedDimension, B>(model, call, first);
      if constexpr (B > 1)
        for (; first < count; ++first)
          detail::chin_tangent_steps_in_local_arrays<FixedDimension, 1>(model, call, first);
      return;
    }
  }
  const std::size_t n = count == 0 ? 0 : call.steps.q.size() / count;
  const std::size_t block = FixedDimension > 0 ? block_states(FixedDimension) : block_states_at_run_time(n);
  std::vector<double> scratch(2 * std::min(block, count) * k * n);
  for (; first < count; first += block)
    detail::chin_tangent_steps_in_place(model, call, n, first, std::min(block, count - first), scratch);
}

// chin_kernel_steps (below) for calls without weights (Expansion false) or with them (true), which the SDK
// instantiates as separate functions (nonsep/sdk/kernels.hpp).
template <std::size_t FixedDimension, bool Expansion, Model M>
void chin_kernel_blocks(const M& model, const ChinStepsCall& call) {
  const std::size_t count = call.count;
  if constexpr (FixedDimension > 0) {
    constexpr std::size_t B = block_states(FixedDimension);
    std::size_t first = 0;
    if constexpr (B > 1)
      for (; first + B <= count; first += B)
        detail::chin_steps_in_local_arrays<FixedDimension, B, Expansion>(model, call, first);
    // Up to three left over (one trajectory; the rounds of a multi-product expansion's terms): a pair, then one,
    // in local arrays, the pair's two chains interleaved in registers.
    if constexpr (B > 2)
      if (count - first == 2 || count - first == 3) {
        detail::chin_steps_in_local_arrays<FixedDimension, 2, Expansion>(model, call, first);
        first += 2;
      }
    if (count - first == 1)
      detail::chin_steps_in_local_arrays<FixedDimension, 1, Expansion>(model, call, first);
    else if (first < count)
      detail::chin_steps_in_place<Expansion>(model, call, FixedDimension, first, count - first);
  } else {
    const std::size_t n = count == 0 ? 0 : call.q.size() / count;
    const std::size_t block = block_states_at_run_time(n);
    for (std::size_t first = 0; first < count; first += block)
      detail::chin_steps_in_place<Expansion>(model, call, n, first, std::min(block, count - first));
  }
}

// The steps of `call` for `model` (its dimension is FixedDimension when that is not 0). Requires the sizes of
// chin_stages: q, p and both gradients count*n numbers, and chin_eps_fit(call.eps.size(), call.substeps, count,
// call.weights.size()). Allocates scratch for an expansion's blocks in the caller's arrays (std::bad_alloc).
template <std::size_t FixedDimension, Model M>
void chin_kernel_steps(const M& model, const ChinStepsCall& call) {
  if (call.weights.empty())
    chin_kernel_blocks<FixedDimension, false>(model, call);
  else
    chin_kernel_blocks<FixedDimension, true>(model, call);
}

}  // namespace nonsep
