#pragma once
// A stepping kernel: the steps of a ChinStepsCall (chin_stages.hpp) with the model's gradients inlined, as the
// plugin SDK instantiates it inside each plugin (one kernel per model, compiled with the model). The flows are
// chin_stages' own; what differs from the evaluation path (ChinBasicStep with a plugin's batched gradients) is only
// the order in which states and steps are visited:
//   - the states go in blocks that take all of the call's steps before the next block starts, so a block stays in
//     the first-level cache (or in registers) instead of the whole batch streaming through memory 17 times a step;
//   - for a dimension N known at compile time (FixedDimension = N > 0), a block of B = block_states(N) states is
//     copied into local arrays whose sizes the compiler knows: one state of dimension <= 4 keeps q, p and both
//     gradients in registers through the nine flows, and a block of B states vectorizes across states. The states
//     left over after the whole blocks go one by one.
//   - with a dimension known only at run time (FixedDimension = 0), blocks of the caller's arrays.
// Each number sees the same operations in the same order as in the evaluation path, so a kernel compiled with the
// evaluation path's flags gives its numbers bit for bit (tests/core/test_chin_kernel.cpp).
//
// Throws what the model throws; the call's arrays then hold a mixture of steps (the caller redoes the call through
// the evaluation path).
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "nonsep/core/chin_stages.hpp"

namespace nonsep {

// The version of what a kernel computes (the ChinStepsCall it takes, chin_stages' flows): a plugin records the
// version it was compiled from, and a host whose core has another one steps that plugin through its evaluations.
// Version 2: a call carries a schedule of sub-steps (ChinStepsCall::substeps).
inline constexpr std::uint64_t chin_kernel_version = 2;

// States per block: 16 numbers of each array for a small fixed dimension, one state from 16 on.
constexpr std::size_t block_states(std::size_t dimension) { return dimension >= 16 ? 1 : 16 / dimension; }
// States per block of the caller's arrays when the dimension is known at run time only: about 512 numbers each.
inline std::size_t block_states_at_run_time(std::size_t dimension) { return std::max<std::size_t>(1, 512 / dimension); }

namespace detail {

// Whether the call's eps holds one entry per state (else one per sub-step, for every state).
inline bool eps_per_state(const ChinStepsCall& call) { return call.substeps == 1 && call.eps.size() != 1; }

// The call's steps for states [first, first + B) of dimension N, in local arrays.
template <std::size_t N, std::size_t B, Model M>
inline void chin_steps_in_local_arrays(const M& model, const ChinStepsCall& call, std::size_t first) {
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
  chin_scheduled_stages(model, ChinStepsCall{call.form, call.coefficients, block_eps, call.substeps, call.steps, B, q,
                                             p, outer_gradient, inner_gradient});
  std::copy_n(q.begin(), size, call.q.begin() + static_cast<std::ptrdiff_t>(offset));
  std::copy_n(p.begin(), size, call.p.begin() + static_cast<std::ptrdiff_t>(offset));
  std::copy_n(outer_gradient.begin(), size, call.outer_gradient.begin() + static_cast<std::ptrdiff_t>(offset));
}

}  // namespace detail

// The steps of `call` for `model` (its dimension is FixedDimension when that is not 0). Requires the sizes of
// chin_stages: q, p and both gradients count*n numbers, and chin_eps_fit(call.eps.size(), call.substeps, count).
template <std::size_t FixedDimension, Model M>
void chin_kernel_steps(const M& model, const ChinStepsCall& call) {
  const std::size_t count = call.count;
  if constexpr (FixedDimension > 0) {
    constexpr std::size_t B = block_states(FixedDimension);
    std::size_t first = 0;
    if constexpr (B > 1)
      for (; first + B <= count; first += B) detail::chin_steps_in_local_arrays<FixedDimension, B>(model, call, first);
    for (; first < count; ++first) detail::chin_steps_in_local_arrays<FixedDimension, 1>(model, call, first);
  } else {
    const std::size_t n = count == 0 ? 0 : call.q.size() / count;
    const std::size_t block = block_states_at_run_time(n);
    for (std::size_t first = 0; first < count; first += block) {
      const std::size_t states = std::min(block, count - first), offset = first * n, size = states * n;
      const std::span<const double> eps = detail::eps_per_state(call) ? call.eps.subspan(first, states) : call.eps;
      chin_scheduled_stages(
          model, ChinStepsCall{call.form, call.coefficients, eps, call.substeps, call.steps, states,
                               call.q.subspan(offset, size), call.p.subspan(offset, size),
                               call.outer_gradient.subspan(offset, size), call.inner_gradient.subspan(offset, size)});
    }
  }
}

}  // namespace nonsep
