#include "nonsep/core/tangent/gauss_linear_stages.hpp"

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
// sums kept in memory made this solve half of a tangent run). The system is factored once (P A = L U, the rows
// swapped whole, L's multipliers below the diagonal), then each vector is solved alone: its numbers are those of
// eliminating every right-hand side alongside the system, operation for operation (the multiplier of a row is
// applied to the same value in the same order; only where the value is kept differs).
template <std::size_t S, std::size_t D>
bool map_by_linear_stages_of(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                             std::span<double> vectors, std::size_t k) {
  constexpr std::size_t M = S * D;
  // J_j(r, c) at jacobians[(j*D + c)*D + r]; the system row-major, row i*D + r for stage i, component r.
  const auto J = [&](std::size_t j, std::size_t r, std::size_t c) { return jacobians[(j * D + c) * D + r]; };
  std::array<double, S * S> weight;  // dt a_ij
  for (std::size_t i = 0; i < S; ++i)
    for (std::size_t j = 0; j < S; ++j) weight[i * S + j] = dt * tableau.a[i * S + j];
  // system = I - dt (A (x) I) diag(J_j)
  std::array<double, M * M> system;
  for (std::size_t i = 0; i < S; ++i)
    for (std::size_t r = 0; r < D; ++r) {
      const std::size_t row = i * D + r;
      for (std::size_t j = 0; j < S; ++j)
        for (std::size_t c = 0; c < D; ++c)
          system[row * M + j * D + c] = (row == j * D + c ? 1.0 : 0.0) - weight[i * S + j] * J(j, r, c);
    }
  // Gaussian elimination with partial pivoting.
  std::array<std::size_t, M> pivots;
  for (std::size_t col = 0; col < M; ++col) {
    std::size_t pivot = col;
    for (std::size_t row = col + 1; row < M; ++row)
      if (std::abs(system[row * M + col]) > std::abs(system[pivot * M + col])) pivot = row;
    pivots[col] = pivot;
    if (pivot != col)
      for (std::size_t c = 0; c < M; ++c) std::swap(system[col * M + c], system[pivot * M + c]);
    const double inverse = 1.0 / system[col * M + col];  // inf for a singular system: the result is then not finite
    for (std::size_t row = col + 1; row < M; ++row) {
      const double factor = system[row * M + col] * inverse;
      system[row * M + col] = factor;
      for (std::size_t c = col + 1; c < M; ++c) system[row * M + c] -= factor * system[col * M + c];
    }
  }
  bool finite = true;
  for (std::size_t v = 0; v < k; ++v) {
    double* z = vectors.data() + v * D;  // dz on entry, dz' on return
    std::array<double, M> products, right;
    for (std::size_t j = 0; j < S; ++j)  // products_j = J_j dz
      for (std::size_t r = 0; r < D; ++r) {
        double sum = 0.0;
        for (std::size_t c = 0; c < D; ++c) sum += J(j, r, c) * z[c];
        products[j * D + r] = sum;
      }
    for (std::size_t i = 0; i < S; ++i)  // right_i = dt sum_j a_ij products_j
      for (std::size_t r = 0; r < D; ++r) {
        double sum = 0.0;
        for (std::size_t j = 0; j < S; ++j) sum += weight[i * S + j] * products[j * D + r];
        right[i * D + r] = sum;
      }
    for (std::size_t col = 0; col < M; ++col)  // P right, then L and U: right becomes dZ
      if (pivots[col] != col) std::swap(right[col], right[pivots[col]]);
    for (std::size_t col = 0; col < M; ++col)
      for (std::size_t row = col + 1; row < M; ++row) right[row] -= system[row * M + col] * right[col];
    for (std::size_t col = M; col-- > 0;) {
      double sum = right[col];
      for (std::size_t c = col + 1; c < M; ++c) sum -= system[col * M + c] * right[c];
      right[col] = sum / system[col * M + col];
    }
    // dz' = dz + dt sum_i b_i (J_i dz + J_i dZ_i): in place, dz being read no more (products holds J_i dz)
    for (std::size_t r = 0; r < D; ++r) {
      double sum = 0.0;
      for (std::size_t i = 0; i < S; ++i) {
        double stage = products[i * D + r];
        for (std::size_t c = 0; c < D; ++c) stage += J(i, r, c) * right[i * D + c];
        sum += dt * tableau.b[i] * stage;
      }
      z[r] += sum;
      finite = finite && std::isfinite(z[r]);
    }
  }
  return finite;
}

// The solvers of every S = 1 .. max_stages and even D with S D <= capacity, at [(S - 1) * columns + D / 2 - 1].
using Solver = bool (*)(const GaussLegendreTableau&, double, std::span<const double>, std::span<double>, std::size_t);
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

bool map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                          std::size_t d, std::span<double> vectors, std::size_t k) {
  const std::size_t s = static_cast<std::size_t>(tableau.stages), m = s * d;
  if (m == 0) return true;  // nothing to solve
  if (m > capacity || k > capacity || d % 2 != 0 || s > static_cast<std::size_t>(GaussLegendreTableau::max_stages))
    throw InvalidArgument(
        "the direct solve of Gauss-Legendre's linear stages takes d = 2n components, s stages and k "
        "vectors with sd <= " +
        std::to_string(capacity) + " and k <= " + std::to_string(capacity) + "; found d = " + std::to_string(d) +
        ", s = " + std::to_string(s) + ", k = " + std::to_string(k));
  return solver_table[(s - 1) * columns + d / 2 - 1](tableau, dt, jacobians, vectors, k);
}

}  // namespace nonsep
