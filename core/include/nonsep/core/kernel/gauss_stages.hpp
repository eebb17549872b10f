#pragma once
// The fixed-point iteration of Gauss-Legendre collocation (schemes/gauss_legendre.hpp says what it solves, in which
// arrangement, and by which stopping rule), written once for its two callers:
//   - GaussLegendre, the host's stepper, iterates a whole batch together, grad H in one batched model call per
//     iteration (a plugin's entries crossed a few times per iteration, not per state);
//   - gauss_kernel_steps below, the stepping kernel a plugin carries (plugin_abi.h gauss_steps, compiled inside the
//     plugin with the model), iterates blocks of 32 states to convergence, a block's stages in arrays that stay in
//     the first-level cache, grad H of the states still iterating in one call per stage, no boundary crossed.
// Both evaluate grad H at the same points, form the next iterate by gauss_next_iterate, stop by gauss_converged and
// add the increment by gauss_compensated_add, in the same order per state: a kernel compiled with the host's flags
// gives the host's numbers bit for bit (tests/core/test_gauss_kernel.cpp).
#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/base/model.hpp"

namespace nonsep {

inline constexpr std::size_t gauss_max_stages = 8;

// std::max by value: the same result (a < b ? b : a), but no reference to a temporary, which keeps GCC from
// vectorizing the loop.
inline double gauss_larger(double a, double b) { return a < b ? b : a; }

// Components e in [first, last) of a stage-major layout (stage i, component e at i*size + e): L^{m+1}_i = hb_i f(z +
// Z^m_i) with f = (dH/dp, -dH/dq) into L_q, L_p, Z^{m+1}_i = sum_j mu_ij L^{m+1}_j into next_q, next_p, and per
// component the largest change |Z^{m+1} - Z^m| and size max(|z|, |Z^{m+1}|) over the stages, and a probe that is
// NaN when some Z^{m+1} is not finite (0 * inf and 0 * NaN are NaN). S, the stage count, is a template argument so
// that the sums unroll and the loop over components vectorizes. The arrays do not overlap (__restrict: without it
// GCC gives up on the many checks for overlap it would need).
template <std::size_t S>
inline void gauss_next_iterate(const double* mu, const double* hb, std::size_t first, std::size_t last,
                               std::size_t size, const double* __restrict dH_dq, const double* __restrict dH_dp,
                               const double* __restrict z_q, const double* __restrict z_p,
                               const double* __restrict start_q, const double* __restrict start_p,
                               double* __restrict L_q, double* __restrict L_p, double* __restrict next_q,
                               double* __restrict next_p, double* __restrict change, double* __restrict scale,
                               double* __restrict probe) {
  for (std::size_t e = first; e < last; ++e) {
    double lq[S], lp[S];
    for (std::size_t j = 0; j < S; ++j) {
      lq[j] = hb[j] * dH_dp[j * size + e];
      lp[j] = hb[j] * -dH_dq[j * size + e];
      L_q[j * size + e] = lq[j];
      L_p[j * size + e] = lp[j];
    }
    double largest_change = 0.0, largest = gauss_larger(std::abs(start_q[e]), std::abs(start_p[e])), nan = 0.0;
    for (std::size_t i = 0; i < S; ++i) {
      double sum_q = 0.0, sum_p = 0.0;
      for (std::size_t j = 0; j < S; ++j) {
        sum_q += mu[i * S + j] * lq[j];
        sum_p += mu[i * S + j] * lp[j];
      }
      next_q[i * size + e] = sum_q;
      next_p[i * size + e] = sum_p;
      largest_change = gauss_larger(
          largest_change, gauss_larger(std::abs(sum_q - z_q[i * size + e]), std::abs(sum_p - z_p[i * size + e])));
      largest = gauss_larger(largest, gauss_larger(std::abs(sum_q), std::abs(sum_p)));
      nan += 0.0 * sum_q + 0.0 * sum_p;
    }
    change[e] = largest_change;
    scale[e] = largest;
    probe[e] = nan;
  }
}

// A functor with the stage count as a template argument: gauss_with_stages(s, f) calls f.template operator()<S>()
// for S = s (1 .. gauss_max_stages; nothing for another s).
template <class F>
inline void gauss_with_stages(std::size_t stages, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (void)((stages == I + 1 ? (f.template operator()<I + 1>(), true) : false) || ...);
  }
  (std::make_index_sequence<gauss_max_stages>());
}

// The stopping rule, per state: delta = the relative change of this iteration, last = that of the one before
// (infinity at the first). Converged when delta is at most one ulp of the state's largest component (nothing left to
// gain), or when it stopped decreasing at round-off (delta >= last and delta <= 64 eps, GNI VIII.6).
inline bool gauss_converged(double delta, double last) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  return delta <= eps || (delta >= last && delta <= 64 * eps);
}

// One state's iteration, judged from its n components' change, scale and probe (gauss_next_iterate): the change
// relative to the state's size, and whether the iterate is finite (the probe sums to NaN when it is not).
struct GaussStateChange {
  double relative;
  bool finite;
};
inline GaussStateChange gauss_state_change(const double* change, const double* scale, const double* probe,
                                           std::size_t n) {
  double largest_change = 0.0, largest = 0.0, nan = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    largest_change = std::max(largest_change, change[k]);
    largest = std::max(largest, scale[k]);
    nan += probe[k];
  }
  return {largest > 0.0 ? largest_change / largest : 0.0, nan == 0.0};
}

// z += increment, compensated: the increment carries the last step's rounding error, and this addition's own
// (TwoSum, exact) is kept in `error` for the next.
inline void gauss_compensated_add(double& z, double increment, double& error) {
  increment += error;
  const double sum = z + increment, increment_part = sum - z;
  error = (z - (sum - increment_part)) + (increment - increment_part);
  z = sum;
}

// Each state's last step, which the next step starts from (GaussLegendre's private state per state, checkpointed):
// a row of gauss_memory_width(n, s) numbers, dt (0: no last step), its end point q and p, the rounding errors of
// its compensated sum (q, p), and the L of its stages (q parts, then p parts, stage-major: stage j, component k at
// j*n + k).
constexpr std::size_t gauss_memory_width(std::size_t n, std::size_t s) { return 1 + 4 * n + 2 * s * n; }

// Whether a step of dt from (q, p) continues the step `row` remembers: the same dt, and q and p where it ended, bit
// for bit.
inline bool gauss_continues(const double* row, const double* q, const double* p, std::size_t n, double dt) {
  if (row[0] != dt) return false;
  for (std::size_t k = 0; k < n; ++k)
    if (std::bit_cast<std::uint64_t>(row[1 + k]) != std::bit_cast<std::uint64_t>(q[k]) ||
        std::bit_cast<std::uint64_t>(row[1 + n + k]) != std::bit_cast<std::uint64_t>(p[k]))
      return false;
  return true;
}

// The starting stages of a step that continues `row` (nu: s x s, row-major, GaussLegendreTableau::nu): Z^0_i =
// sum_j nu_ij L_j, the last step's collocation polynomial extrapolated to this step's stage points, stage i
// component k into z_q[i*stride + k] and z_p[i*stride + k].
inline void gauss_extrapolate(const double* row, const double* nu, std::size_t s, std::size_t n, double* z_q,
                              double* z_p, std::size_t stride) {
  const double* L_q = row + 1 + 4 * n;
  const double* L_p = L_q + s * n;
  for (std::size_t i = 0; i < s; ++i)
    for (std::size_t k = 0; k < n; ++k) {
      double sum_q = 0.0, sum_p = 0.0;
      for (std::size_t j = 0; j < s; ++j) {
        sum_q += nu[i * s + j] * L_q[j * n + k];
        sum_p += nu[i * s + j] * L_p[j * n + k];
      }
      z_q[i * stride + k] = sum_q;
      z_p[i * stride + k] = sum_p;
    }
}

// A state's step into its row: dt, its end point q, p, the rounding errors of its sum and its L (stage j, component
// k at L_q[j*stride + k]).
inline void gauss_remember(double* row, double dt, const double* q, const double* p, const double* compensation_q,
                           const double* compensation_p, const double* L_q, const double* L_p, std::size_t stride,
                           std::size_t s, std::size_t n) {
  row[0] = dt;
  for (std::size_t k = 0; k < n; ++k) {
    row[1 + k] = q[k];
    row[1 + n + k] = p[k];
    row[1 + 2 * n + k] = compensation_q[k];
    row[1 + 3 * n + k] = compensation_p[k];
  }
  double* to_q = row + 1 + 4 * n;
  double* to_p = to_q + s * n;
  for (std::size_t j = 0; j < s; ++j)
    for (std::size_t k = 0; k < n; ++k) {
      to_q[j * n + k] = L_q[j * stride + k];
      to_p[j * n + k] = L_p[j * stride + k];
    }
}

// How one state's iteration ended.
enum class GaussOutcome : std::uint8_t { converged = 0, not_finite = 1, no_convergence = 2 };

// One step of Gauss-Legendre collocation of `count` states (the batch layout: component k of state b at b*n + k),
// each iterated to convergence (plugin_abi.h nonsep_gauss_steps_args is this call across the boundary):
//   form, stages (1 .. 8), max_iterations (>= 1), dt, mu (s x s, row-major) and hb (s numbers, fl(dt b_i)): the
//                  method; nu (s x s) the starting values' extrapolation, or empty to start every step from Z = 0;
//   q, p           in, the states; out, the converged states advanced (the others unspecified);
//   memory         each state's last step (a row of gauss_memory_width(n, s) numbers; a state starts from it where
//                  it continues it, gauss_continues, else from Z = 0 and no carried rounding error);
//   next_memory    out, the same of this step for the converged states (the others unspecified);
//   points_q/_p    out, for converged states, the stage points z + Z_i at which f was last evaluated, stage-major over
//                  the batch (stage i, component k of state b at i*count*n + b*n + k);
//   iterations, outcome   out, per state.
struct GaussStepsCall {
  HamiltonianForm form;
  std::size_t stages;
  int max_iterations;
  double dt;
  std::span<const double> mu, hb, nu;
  std::size_t count;
  std::span<double> q, p;
  std::span<const double> memory;
  std::span<double> next_memory, points_q, points_p;
  std::span<int> iterations;
  std::span<GaussOutcome> outcome;
};

// A model that may take a Gauss step itself, with grad H inlined (a plugin's kernel):
//   m.gauss_steps(call) -> bool   true when it took call's step as gauss_kernel_steps does (the same numbers for code
//                                 built alike), false when no kernel is at hand or it failed inside (then the call's
//                                 arrays are unspecified, and the caller takes the step through its own path).
template <class M>
concept ModelWithGaussSteps = requires(const M& m, const GaussStepsCall& call) {
  { m.gauss_steps(call) } -> std::same_as<bool>;
};

// The states of a kernel's block (gauss_kernel_steps): enough for the model's loops over the block's stage points to
// run at the machine's throughput, few enough that a block's stages stay in the first-level cache.
inline constexpr std::size_t gauss_block_states = 32;

// The step of `call` (above), in blocks of gauss_block_states states. A block's states iterating are kept in its
// first slots: each iteration evaluates grad H at their s stage points in s calls (one per stage, the slots' points
// contiguous), forms their next iterate, and a state that stops hands its slot to the block's last state still
// iterating. So grad H is evaluated exactly as often as the evaluation path counts, and each state's numbers are
// those of its own iteration wherever it sits. Throws what the model throws; the call's arrays are then unspecified.
template <std::size_t FixedDimension = 0, HamiltonianModel M>
void gauss_kernel_steps(const M& model, const GaussStepsCall& call) {
  gauss_with_stages(call.stages, [&]<std::size_t S>() {
    const std::size_t n = FixedDimension > 0 ? FixedDimension : static_cast<std::size_t>(model.dimension()),
                      size = call.count * n, row_width = gauss_memory_width(n, S);
    const std::size_t block = gauss_block_states * n, stage = S * block;
    HamiltonianGradient gradient(call.form);
    double mu[S * S], hb[S];
    std::copy_n(call.mu.data(), S * S, mu);
    std::copy_n(call.hb.data(), S, hb);
    // A block's numbers by slot, stage-major (stage i, component k of slot j at i*width + j*n + k).
    std::vector<double> work(4 * block + 8 * stage + 3 * block + 2 * stage);
    double* start_q = work.data();
    double* start_p = start_q + block;
    double* compensation_q = start_p + block;
    double* compensation_p = compensation_q + block;
    double* z_q = compensation_p + block;
    double* z_p = z_q + stage;
    double* next_q = z_p + stage;
    double* next_p = next_q + stage;
    double* point_q = next_p + stage;
    double* point_p = point_q + stage;
    double* dH_dq = point_p + stage;
    double* dH_dp = dH_dq + stage;
    double* L_q = dH_dp + stage;
    double* L_p = L_q + stage;
    double* change = L_p + stage;
    double* scale = change + block;
    double* probe = scale + block;
    double last[gauss_block_states];
    std::size_t state_of[gauss_block_states];
    for (std::size_t first = 0; first < call.count; first += gauss_block_states) {
      const std::size_t states = std::min(gauss_block_states, call.count - first), width = states * n;
      for (std::size_t e = 0; e < width; ++e) {
        start_q[e] = call.q[first * n + e];
        start_p[e] = call.p[first * n + e];
      }
      std::fill_n(z_q, S * width, 0.0);
      std::fill_n(z_p, S * width, 0.0);
      std::fill_n(compensation_q, width, 0.0);
      std::fill_n(compensation_p, width, 0.0);
      for (std::size_t j = 0; j < states; ++j) {
        const std::size_t b = first + j;
        state_of[j] = b;
        last[j] = std::numeric_limits<double>::infinity();
        call.iterations[b] = 0;
        call.outcome[b] = GaussOutcome::no_convergence;
        const double* row = call.memory.data() + b * row_width;
        if (!gauss_continues(row, start_q + j * n, start_p + j * n, n, call.dt)) continue;
        std::copy_n(row + 1 + 2 * n, n, compensation_q + j * n);
        std::copy_n(row + 1 + 3 * n, n, compensation_p + j * n);
        if (!call.nu.empty()) gauss_extrapolate(row, call.nu.data(), S, n, z_q + j * n, z_p + j * n, width);
      }
      // Slot `to` takes slot `from`'s state, as far as its next iteration needs it (its next iterate included).
      const auto move_slot = [&](std::size_t from, std::size_t to) {
        for (std::size_t k = 0; k < n; ++k) {
          start_q[to * n + k] = start_q[from * n + k];
          start_p[to * n + k] = start_p[from * n + k];
          compensation_q[to * n + k] = compensation_q[from * n + k];
          compensation_p[to * n + k] = compensation_p[from * n + k];
          for (std::size_t i = 0; i < S; ++i) {
            next_q[i * width + to * n + k] = next_q[i * width + from * n + k];
            next_p[i * width + to * n + k] = next_p[i * width + from * n + k];
          }
        }
        last[to] = last[from];
        state_of[to] = state_of[from];
      };
      std::size_t left = states;
      for (int m = 0; m < call.max_iterations && left > 0; ++m) {
        const std::size_t active = left * n;
        for (std::size_t i = 0; i < S; ++i) {
          for (std::size_t e = 0; e < active; ++e) {
            point_q[i * width + e] = start_q[e] + z_q[i * width + e];
            point_p[i * width + e] = start_p[e] + z_p[i * width + e];
          }
          gradient.evaluate(model, std::span<const double>(point_q + i * width, active),
                            std::span<const double>(point_p + i * width, active),
                            std::span<double>(dH_dq + i * width, active), std::span<double>(dH_dp + i * width, active),
                            left);
        }
        gauss_next_iterate<S>(mu, hb, 0, active, width, dH_dq, dH_dp, z_q, z_p, start_q, start_p, L_q, L_p, next_q,
                              next_p, change, scale, probe);
        for (std::size_t j = left; j-- > 0;) {
          const std::size_t b = state_of[j];
          ++call.iterations[b];
          const auto [relative, finite] = gauss_state_change(change + j * n, scale + j * n, probe + j * n, n);
          if (finite && !gauss_converged(relative, last[j])) {
            last[j] = relative;
            continue;
          }
          if (!finite) {
            call.outcome[b] = GaussOutcome::not_finite;
          } else {
            call.outcome[b] = GaussOutcome::converged;
            for (std::size_t i = 0; i < S; ++i)
              for (std::size_t k = 0; k < n; ++k) {
                call.points_q[i * size + b * n + k] = point_q[i * width + j * n + k];
                call.points_p[i * size + b * n + k] = point_p[i * width + j * n + k];
              }
            for (std::size_t k = 0; k < n; ++k) {
              double sum_q = 0.0, sum_p = 0.0;
              for (std::size_t i = 0; i < S; ++i) {
                sum_q += L_q[i * width + j * n + k];
                sum_p += L_p[i * width + j * n + k];
              }
              gauss_compensated_add(call.q[b * n + k], sum_q, compensation_q[j * n + k]);
              gauss_compensated_add(call.p[b * n + k], sum_p, compensation_p[j * n + k]);
            }
            gauss_remember(call.next_memory.data() + b * row_width, call.dt, call.q.data() + b * n,
                           call.p.data() + b * n, compensation_q + j * n, compensation_p + j * n, L_q + j * n,
                           L_p + j * n, width, S, n);
          }
          // The slots above j still iterate (they were decided before it): the last of them takes j's place.
          if (j != left - 1) move_slot(left - 1, j);
          --left;
        }
        std::swap(z_q, next_q);
        std::swap(z_p, next_p);
      }
    }
  });
}

}  // namespace nonsep
