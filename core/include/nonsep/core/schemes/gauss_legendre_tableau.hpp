#pragma once
// The Butcher tableau of Gauss-Legendre collocation (gauss_legendre.hpp) with the coefficients of its round-off
// arrangement (mu) and of its starting values (nu), computed for s = 1 .. 8 stages.
#include <cmath>
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/error.hpp"

namespace nonsep {

// The Butcher tableau of the s-stage Gauss-Legendre method (s = 1 .. 8): a row-major s x s, b, c, mu (row-major,
// mu_ij = a_ij / b_j with mu_ij + mu_ji = 1 exactly) and nu (row-major: the starting values, nu_ij = e_ij / b_j with
// e_ij the integral of the j-th Lagrange polynomial over [1, 1 + c_i], so that sum_j nu_ij L_j of one step is the
// step's collocation polynomial extrapolated to the next step's stage points). Computed in long double and rounded
// once: the nodes c_i are
// the roots of the Legendre polynomial P_s mapped to [0, 1] (Newton's method, mirrored so that c_{s+1-i} = 1 - c_i
// and b_{s+1-i} = b_i), b_i the Gauss weights, a_ij the integral of the j-th Lagrange polynomial over [0, c_i] by the
// same quadrature scaled to that interval (exact: the polynomial has degree s - 1), e_ij the same over [1, 1 + c_i].
struct GaussLegendreTableau {
  static constexpr int max_stages = 8;
  int stages;
  std::vector<double> a, b, c, mu, nu;

  // Throws InvalidArgument unless 1 <= stages <= max_stages.
  static void check_stages(int stages) {
    if (stages < 1 || stages > max_stages)
      throw InvalidArgument("Gauss-Legendre collocation has 1 to 8 stages, orders 2 to 16 (found " +
                            std::to_string(stages) + ")");
  }
  // Throws InvalidArgument unless 1 <= stages <= max_stages.
  static GaussLegendreTableau for_stages(int stages) {
    check_stages(stages);
    using Real = long double;
    const std::size_t s = static_cast<std::size_t>(stages);
    std::vector<Real> c(s), b(s);
    // P_s(x) and P_s'(x) by the three-term recurrence.
    const auto legendre = [s](Real x) {
      Real previous = 1, current = x;
      for (std::size_t k = 1; k < s; ++k) {
        const Real next =
            (static_cast<Real>(2 * k + 1) * x * current - static_cast<Real>(k) * previous) / static_cast<Real>(k + 1);
        previous = current;
        current = next;
      }
      const Real derivative = static_cast<Real>(s) * (x * current - previous) / (x * x - 1);
      return std::pair{current, derivative};
    };
    const Real pi = 3.14159265358979323846264338327950288L;
    for (std::size_t i = 0; i < (s + 1) / 2; ++i) {
      Real x = std::cos(pi * (static_cast<Real>(i) + 0.75L) / (static_cast<Real>(s) + 0.5L));  // the i-th largest
      if (2 * i + 1 == s) x = 0;  // the middle root of an odd s
      for (int iteration = 0; iteration < 100 && x != 0; ++iteration) {
        const auto [value, derivative] = legendre(x);
        const Real next = x - value / derivative;
        if (next == x) break;
        x = next;
      }
      const Real slope = legendre(x).second, weight = 1 / ((1 - x * x) * slope * slope);  // half the Gauss weight
      c[i] = (1 - x) / 2;
      c[s - 1 - i] = (1 + x) / 2;
      b[i] = b[s - 1 - i] = weight;
    }
    const auto lagrange = [&](std::size_t j, Real t) {
      Real value = 1;
      for (std::size_t m = 0; m < s; ++m)
        if (m != j) value *= (t - c[m]) / (c[j] - c[m]);
      return value;
    };
    GaussLegendreTableau tableau{stages,
                                 std::vector<double>(s * s),
                                 std::vector<double>(s),
                                 std::vector<double>(s),
                                 std::vector<double>(s * s),
                                 std::vector<double>(s * s)};
    for (std::size_t i = 0; i < s; ++i) {
      tableau.b[i] = static_cast<double>(b[i]);
      tableau.c[i] = static_cast<double>(c[i]);
      for (std::size_t j = 0; j < s; ++j) {
        Real integral = 0, beyond = 0;
        for (std::size_t k = 0; k < s; ++k) {
          integral += b[k] * lagrange(j, c[i] * c[k]);
          beyond += b[k] * lagrange(j, 1 + c[i] * c[k]);
        }
        integral *= c[i];
        tableau.nu[i * s + j] = static_cast<double>(c[i] * beyond / b[j]);
        tableau.a[i * s + j] = static_cast<double>(integral);
        // Below the diagonal mu_ij lies in [1/2, 2], where 1 - mu_ij is exact (Sterbenz).
        if (j < i) {
          tableau.mu[i * s + j] = static_cast<double>(integral / b[j]);
          tableau.mu[j * s + i] = 1.0 - tableau.mu[i * s + j];
        }
      }
      tableau.mu[i * s + i] = 0.5;
    }
    return tableau;
  }
};

}  // namespace nonsep
