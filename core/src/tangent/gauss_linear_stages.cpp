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

// The solve for a system of M = 2ns rows known at compile time, so that its loops unroll and vectorize (the paper2d
// tangent run of bench/tangent_cost.py: 11% less CPU than with M known at run time only); k vectors.
template <std::size_t M>
bool map_by_linear_stages_of(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                             std::size_t d, std::span<double> vectors, std::size_t k) {
  const std::size_t s = static_cast<std::size_t>(tableau.stages), n = d;
  constexpr std::size_t m = M;
  // J_j(r, c) at jacobians[(j*n + c)*n + r]; dz(c, v) at vectors[v*n + c]. Row-major: system (m x m), products and
  // right (m x k), row i*n + r for stage i, component r.
  const auto J = [&](std::size_t j, std::size_t r, std::size_t c) { return jacobians[(j * n + c) * n + r]; };
  // Every entry of the system is written below (s n = M); zeroed first for the compiler, which cannot see that.
  std::array<double, M * M> system{};
  std::array<double, M * capacity> products, right;
  for (std::size_t j = 0; j < s; ++j)  // products_j = J_j dz
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t v = 0; v < k; ++v) {
        double sum = 0.0;
        for (std::size_t c = 0; c < n; ++c) sum += J(j, r, c) * vectors[v * n + c];
        products[(j * n + r) * k + v] = sum;
      }
  // system = I - dt (A (x) I) diag(J_j), right_i = dt sum_j a_ij products_j
  for (std::size_t i = 0; i < s; ++i)
    for (std::size_t r = 0; r < n; ++r) {
      const std::size_t row = i * n + r;
      for (std::size_t v = 0; v < k; ++v) right[row * k + v] = 0.0;
      for (std::size_t j = 0; j < s; ++j) {
        const double weight = dt * tableau.a[i * s + j];
        for (std::size_t c = 0; c < n; ++c)
          system[row * m + j * n + c] = (row == j * n + c ? 1.0 : 0.0) - weight * J(j, r, c);
        for (std::size_t v = 0; v < k; ++v) right[row * k + v] += weight * products[(j * n + r) * k + v];
      }
    }
  // Gaussian elimination with partial pivoting, applied to the right-hand sides alongside.
  for (std::size_t col = 0; col < m; ++col) {
    std::size_t pivot = col;
    for (std::size_t row = col + 1; row < m; ++row)
      if (std::abs(system[row * m + col]) > std::abs(system[pivot * m + col])) pivot = row;
    if (pivot != col) {
      for (std::size_t c = col; c < m; ++c) std::swap(system[col * m + c], system[pivot * m + c]);
      for (std::size_t v = 0; v < k; ++v) std::swap(right[col * k + v], right[pivot * k + v]);
    }
    const double inverse = 1.0 / system[col * m + col];  // inf for a singular system: the result is then not finite
    for (std::size_t row = col + 1; row < m; ++row) {
      const double factor = system[row * m + col] * inverse;
      for (std::size_t c = col + 1; c < m; ++c) system[row * m + c] -= factor * system[col * m + c];
      for (std::size_t v = 0; v < k; ++v) right[row * k + v] -= factor * right[col * k + v];
    }
  }
  for (std::size_t col = m; col-- > 0;) {  // back substitution: right becomes dZ
    for (std::size_t v = 0; v < k; ++v) {
      double sum = right[col * k + v];
      for (std::size_t c = col + 1; c < m; ++c) sum -= system[col * m + c] * right[c * k + v];
      right[col * k + v] = sum / system[col * m + col];
    }
  }
  // dz' = dz + dt sum_i b_i (J_i dz + J_i dZ_i)
  bool finite = true;
  for (std::size_t v = 0; v < k; ++v)
    for (std::size_t r = 0; r < n; ++r) {
      double sum = 0.0;
      for (std::size_t i = 0; i < s; ++i) {
        double stage = products[(i * n + r) * k + v];
        for (std::size_t c = 0; c < n; ++c) stage += J(i, r, c) * right[(i * n + c) * k + v];
        sum += dt * tableau.b[i] * stage;
      }
      vectors[v * n + r] += sum;
      finite = finite && std::isfinite(vectors[v * n + r]);
    }
  return finite;
}

template <std::size_t... M>
bool dispatch(std::size_t m, std::index_sequence<M...>, const GaussLegendreTableau& tableau, double dt,
              std::span<const double> jacobians, std::size_t d, std::span<double> vectors, std::size_t k) {
  bool finite = true;  // m = 0: nothing to solve
  static_cast<void>(
      ((m == M + 1 && (finite = map_by_linear_stages_of<M + 1>(tableau, dt, jacobians, d, vectors, k), true)) || ...));
  return finite;
}

}  // namespace

bool map_by_linear_stages(const GaussLegendreTableau& tableau, double dt, std::span<const double> jacobians,
                          std::size_t d, std::span<double> vectors, std::size_t k) {
  const std::size_t m = static_cast<std::size_t>(tableau.stages) * d;
  if (m > capacity || k > capacity)
    throw InvalidArgument(
        "the direct solve of Gauss-Legendre's linear stages takes 2ns <= " + std::to_string(capacity) +
        " and k <= " + std::to_string(capacity) + "; found 2ns = " + std::to_string(m) + ", k = " + std::to_string(k));
  return dispatch(m, std::make_index_sequence<capacity>(), tableau, dt, jacobians, d, vectors, k);
}

}  // namespace nonsep
