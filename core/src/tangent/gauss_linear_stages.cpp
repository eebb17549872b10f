#include "nonsep/core/tangent/gauss_linear_stages.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "nonsep/core/base/error.hpp"

namespace nonsep {
namespace {

// The system has at most 32 rows (the direct solve is taken for 2ns <= 32 only), so it lives on the stack and is
// eliminated by hand: Eigen's LU, dynamic or of fixed capacity, spent a fifth of a paper1d tangent run (1 degree of
// freedom, 3 stages: a 6 x 6 system) in its blocked paths and dispatch (measured with perf); these loops do the same
// partial-pivoting elimination without them.
constexpr std::size_t capacity = 32;

// The solve for S stages of D = 2n components, both known at compile time so that every loop has fixed bounds
// (bench/tangent_cost.py, paper1d: with only the size 2ns fixed, the loops over the vectors and components and the
// sums kept in memory made this solve half of a tangent run), for L states at once: every number is an array of L
// lanes, one state each, and each lane takes the operations of a solve of its state alone in the same order, so that
// the elimination's long chains of dependent operations of one state overlap with the other states'. The system is
// factored once (P A = L U, the rows swapped whole, L's multipliers below the diagonal), then each vector is solved
// alone: its numbers are those of eliminating every right-hand side alongside the system, operation for operation
// (the multiplier of a row is applied to the same value in the same order; only where the value is kept differs).
//
// Compiled by GCC for x86-64 (ELF), each solve is cloned for AVX-512 and AVX2 besides the build's instruction set and
// the widest the processor runs is taken at load time (8 lanes are one AVX-512 register); core/CMakeLists.txt
// compiles this file with -ffp-contract=off, so no multiply and add are fused and every clone gives the baseline's
// numbers bit for bit. (Clang does not clone function templates: there the build's instruction set alone.)
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__)
#define NONSEP_LINEAR_STAGES_CLONES [[gnu::target_clones("avx512f", "avx2", "default")]]
#else
#define NONSEP_LINEAR_STAGES_CLONES
#endif
template <std::size_t S, std::size_t D, std::size_t L>
NONSEP_LINEAR_STAGES_CLONES unsigned eliminate_lanes(const GaussLegendreTableau& tableau, double dt,
                                                     std::span<const double> jacobians, std::span<double> vectors,
                                                     std::size_t k, std::size_t states) {
  constexpr std::size_t M = S * D;
  using Lanes = std::array<double, L>;
  // J_j(r, c) of lane l at Js[(j*D + c)*D + r][l], from state l's jacobians[(j*D + c)*D + r] (lanes past `states`
  // repeat state 0, and are dropped).
  std::array<Lanes, S * D * D> Js;
  for (std::size_t e = 0; e < S * D * D; ++e)
    for (std::size_t l = 0; l < L; ++l) Js[e][l] = jacobians[(l < states ? l : 0) * S * D * D + e];
  const auto J = [&](std::size_t j, std::size_t r, std::size_t c) -> const Lanes& { return Js[(j * D + c) * D + r]; };
  std::array<double, S * S> weight;  // dt a_ij
  for (std::size_t i = 0; i < S; ++i)
    for (std::size_t j = 0; j < S; ++j) weight[i * S + j] = dt * tableau.a[i * S + j];
  // system = I - dt (A (x) I) diag(J_j), row-major, row i*D + r for stage i, component r
  std::array<Lanes, M * M> system;
  for (std::size_t i = 0; i < S; ++i)
    for (std::size_t r = 0; r < D; ++r) {
      const std::size_t row = i * D + r;
      for (std::size_t j = 0; j < S; ++j)
        for (std::size_t c = 0; c < D; ++c)
          for (std::size_t l = 0; l < L; ++l)
            system[row * M + j * D + c][l] = (row == j * D + c ? 1.0 : 0.0) - weight[i * S + j] * J(j, r, c)[l];
    }
  // Gaussian elimination with partial pivoting, each lane its own pivots.
  std::array<std::array<std::size_t, L>, M> pivots;
  for (std::size_t col = 0; col < M; ++col) {
    Lanes pivot, largest;  // the pivot's row kept as a double, so that the search is a select of doubles
    for (std::size_t l = 0; l < L; ++l) {
      pivot[l] = static_cast<double>(col);
      largest[l] = std::abs(system[col * M + col][l]);
    }
    for (std::size_t row = col + 1; row < M; ++row)
      for (std::size_t l = 0; l < L; ++l) {
        const double size = std::abs(system[row * M + col][l]);
        pivot[l] = size > largest[l] ? static_cast<double>(row) : pivot[l];
        largest[l] = size > largest[l] ? size : largest[l];
      }
    for (std::size_t l = 0; l < L; ++l) pivots[col][l] = static_cast<std::size_t>(pivot[l]);
    for (std::size_t l = 0; l < L; ++l)
      if (pivots[col][l] != col)
        for (std::size_t c = 0; c < M; ++c) std::swap(system[col * M + c][l], system[pivots[col][l] * M + c][l]);
    Lanes inverse;  // inf for a singular system: the result is then not finite
    for (std::size_t l = 0; l < L; ++l) inverse[l] = 1.0 / system[col * M + col][l];
    for (std::size_t row = col + 1; row < M; ++row) {
      Lanes factor;
      for (std::size_t l = 0; l < L; ++l) {
        factor[l] = system[row * M + col][l] * inverse[l];
        system[row * M + col][l] = factor[l];
      }
      for (std::size_t c = col + 1; c < M; ++c)
        for (std::size_t l = 0; l < L; ++l) system[row * M + c][l] -= factor[l] * system[col * M + c][l];
    }
  }
  std::array<bool, L> finite;
  finite.fill(true);
  for (std::size_t v = 0; v < k; ++v) {
    std::array<Lanes, D> z;  // dz on entry, dz' at the end
    for (std::size_t c = 0; c < D; ++c)
      for (std::size_t l = 0; l < L; ++l) z[c][l] = vectors[((l < states ? l : 0) * k + v) * D + c];
    std::array<Lanes, M> products, right;
    for (std::size_t j = 0; j < S; ++j)  // products_j = J_j dz
      for (std::size_t r = 0; r < D; ++r) {
        Lanes sum{};
        for (std::size_t c = 0; c < D; ++c)
          for (std::size_t l = 0; l < L; ++l) sum[l] += J(j, r, c)[l] * z[c][l];
        products[j * D + r] = sum;
      }
    for (std::size_t i = 0; i < S; ++i)  // right_i = dt sum_j a_ij products_j
      for (std::size_t r = 0; r < D; ++r) {
        Lanes sum{};
        for (std::size_t j = 0; j < S; ++j)
          for (std::size_t l = 0; l < L; ++l) sum[l] += weight[i * S + j] * products[j * D + r][l];
        right[i * D + r] = sum;
      }
    for (std::size_t col = 0; col < M; ++col)  // P right, then L and U: right becomes dZ
      for (std::size_t l = 0; l < L; ++l)
        if (pivots[col][l] != col) std::swap(right[col][l], right[pivots[col][l]][l]);
    for (std::size_t col = 0; col < M; ++col) {
      const Lanes solved = right[col];  // a copy, so that the compiler sees no overlap and takes the lanes together
      for (std::size_t row = col + 1; row < M; ++row)
        for (std::size_t l = 0; l < L; ++l) right[row][l] -= system[row * M + col][l] * solved[l];
    }
    for (std::size_t col = M; col-- > 0;) {
      Lanes sum = right[col];
      for (std::size_t c = col + 1; c < M; ++c)
        for (std::size_t l = 0; l < L; ++l) sum[l] -= system[col * M + c][l] * right[c][l];
      for (std::size_t l = 0; l < L; ++l) right[col][l] = sum[l] / system[col * M + col][l];
    }
    // dz' = dz + dt sum_i b_i (J_i dz + J_i dZ_i), products holding J_i dz
    for (std::size_t r = 0; r < D; ++r) {
      Lanes sum{};
      for (std::size_t i = 0; i < S; ++i) {
        Lanes stage = products[i * D + r];
        for (std::size_t c = 0; c < D; ++c)
          for (std::size_t l = 0; l < L; ++l) stage[l] += J(i, r, c)[l] * right[i * D + c][l];
        for (std::size_t l = 0; l < L; ++l) sum[l] += dt * tableau.b[i] * stage[l];
      }
      for (std::size_t l = 0; l < L; ++l) {
        z[r][l] += sum[l];
        finite[l] = finite[l] && std::isfinite(z[r][l]);
      }
    }
    for (std::size_t l = 0; l < states; ++l)
      for (std::size_t c = 0; c < D; ++c) vectors[(l * k + v) * D + c] = z[c][l];
  }
  unsigned failed = 0;
  for (std::size_t l = 0; l < states; ++l) failed |= finite[l] ? 0u : 1u << l;
  return failed;
}

// The states of a call in chunks of eight lanes, or four where the system and the Jacobians of eight would take more
// than 80 KB, so that a solve fits the smallest thread stacks in use (128 KB; the largest frame, gauss 8 stages with
// 2n = 4 on eight lanes, is 88 KB with the AVX-512 clone's other arrays).
template <std::size_t S, std::size_t D>
unsigned map_by_linear_stages_of(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                                 std::span<double> vectors, std::size_t k, std::size_t states) {
  constexpr std::size_t eight_lanes_bytes = (S * D * S * D + S * D * D) * linear_stage_lanes * sizeof(double);
  constexpr std::size_t L = eight_lanes_bytes <= 80 * 1024 ? linear_stage_lanes : linear_stage_lanes / 2;
  unsigned failed = 0;
  for (std::size_t first = 0; first < states; first += L) {
    const std::size_t chunk = std::min(L, states - first);
    failed |= eliminate_lanes<S, D, L>(tableau, dt, jacobians.subspan(first * S * D * D),
                                       vectors.subspan(first * k * D), k, chunk)
              << first;
  }
  return failed;
}

// The solvers of every S = 1 .. max_stages and even D with S D <= capacity, at [(S - 1) * columns + D / 2 - 1].
using Solver = unsigned (*)(const GaussLegendreTableau&, double, std::span<const double>, std::span<double>,
                            std::size_t, std::size_t);
constexpr std::size_t columns = capacity / 2;  // D = 2, 4, .., capacity

template <std::size_t S, std::size_t D>
constexpr Solver solver_of() {
  if constexpr (S * D <= capacity)
    return &map_by_linear_stages_of<S, D>;
  else
    return nullptr;
}
template <std::size_t... I>
constexpr std::array<Solver, sizeof...(I)> solvers(std::index_sequence<I...>) {
  return {solver_of<I / columns + 1, 2 * (I % columns + 1)>()...};
}
constexpr auto solver_table =
    solvers(std::make_index_sequence<static_cast<std::size_t>(GaussLegendreTableau::max_stages) * columns>());

}  // namespace

unsigned map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                              std::size_t d, std::span<double> vectors, std::size_t k, std::size_t states) {
  const std::size_t s = static_cast<std::size_t>(tableau.stages), m = s * d;
  if (m == 0 || states == 0) return 0;  // nothing to solve
  if (m > capacity || k > capacity || d % 2 != 0 || s > static_cast<std::size_t>(GaussLegendreTableau::max_stages) ||
      states > linear_stage_lanes)
    throw InvalidArgument(
        "the direct solve of Gauss-Legendre's linear stages takes d = 2n components, s stages, k vectors and up "
        "to " +
        std::to_string(linear_stage_lanes) + " states with sd <= " + std::to_string(capacity) +
        " and k <= " + std::to_string(capacity) + "; found d = " + std::to_string(d) + ", s = " + std::to_string(s) +
        ", k = " + std::to_string(k) + ", " + std::to_string(states) + " states");
  if (jacobians.size() < states * s * d * d || vectors.size() < states * k * d)
    throw InvalidArgument("the direct solve of Gauss-Legendre's linear stages: found " +
                          std::to_string(jacobians.size()) + " Jacobian entries and " + std::to_string(vectors.size()) +
                          " vector components for " + std::to_string(states) + " states; needed " +
                          std::to_string(states * s * d * d) + " and " + std::to_string(states * k * d));
  return solver_table[(s - 1) * columns + d / 2 - 1](tableau, dt, jacobians, vectors, k, states);
}

bool map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                          std::size_t d, std::span<double> vectors, std::size_t k) {
  return map_by_linear_stages(tableau, dt, jacobians, d, vectors, k, 1) == 0;
}

}  // namespace nonsep
