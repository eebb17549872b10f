#pragma once
// A periodic chain of n sites, the large-n model: on site i a momentum p_i and a displacement q_i (i mod n),
//   T(p) = sum_i f(p_i),                     f(p) = p^2/2 + a p^4/12      (a = "kinetic_quartic" >= 0),
//   V(q) = sum_i [q_i^2/2 + W(q_{i+1} - q_i)],  W(r) = k r^2/2 + b r^4/4    (k = "coupling", b = "bond_quartic"),
// and the solved Hamiltonian (TTV) H = sum_ij f'(p_i) V_ij(q) f'(p_j), with f'(p) = p + a p^3/3 and the
// tridiagonal (periodic) Hessian
//   V_ii = 1 + W''(q_{i+1} - q_i) + W''(q_i - q_{i-1}),   V_i,i+1 = -W''(q_{i+1} - q_i),   W''(r) = k + 3 b r^2.
// Physically: for a = 0 it is a chain of particles whose inverse mass matrix I + k L (L the periodic lattice
// Laplacian) is stiffened by the strain of each bond (b r^2): a lattice with position-dependent, nearest-neighbour
// inverse mass, H = p^T M^-1(q) p, non-separable as soon as b != 0; a != 0 makes the kinetic energy non-quadratic
// too (f' replaces p). Every evaluation is O(n): a gradient, a Hessian-vector product and H itself.
//
// The gradients are templates over the number type, so the SDK differentiates them (not T and V) for the
// directional third derivatives and the (dense, n x n) Hessians; the Hessian-vector products and the product term
// of H (energy_TTV, energy_VVT) are written out; the
// dimension is the parameter "sites", 3 .. Capacity. LatticeChainModel<Capacity> with a small Capacity also compiles T
// and V for the SDK's capacity-sized dual numbers (the tests compare the two ways of differentiating).
#include <cstddef>
#include <nonsep/plugin_sdk.hpp>
#include <span>

template <std::size_t Capacity>
struct LatticeChainModel {
  static constexpr std::size_t max_dimension = Capacity;
  static constexpr const char* dimension_parameter = "sites";
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "sites",
                                                           .type = nonsep::sdk::ParameterType::integer,
                                                           .default_value = 16,
                                                           .minimum = 3,
                                                           .maximum = static_cast<double>(Capacity),
                                                           .description = "number of sites n (the dimension)"},
                                                          {.name = "kinetic_quartic",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 1.0,
                                                           .minimum = 0.0,
                                                           .description = "a in f(p) = p^2/2 + a p^4/12"},
                                                          {.name = "coupling",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 0.5,
                                                           .minimum = 0.0,
                                                           .description = "k in W(r) = k r^2/2 + b r^4/4"},
                                                          {.name = "bond_quartic",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 1.0,
                                                           .minimum = 0.0,
                                                           .description = "b in W(r) = k r^2/2 + b r^4/4"}};

  explicit LatticeChainModel(const nonsep::sdk::ParameterValues& values)
      : a(values.number("kinetic_quartic")), k(values.number("coupling")), b(values.number("bond_quartic")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    S sum = 0.0;
    for (const S& pi : p) {
      const S p2 = pi * pi;
      sum += p2 / 2.0 + a * p2 * p2 / 12.0;
    }
    return sum;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const std::size_t n = q.size();
    S sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const S r = q[i + 1 == n ? 0 : i + 1] - q[i];
      const S r2 = r * r;
      sum += q[i] * q[i] / 2.0 + k * r2 / 2.0 + b * r2 * r2 / 4.0;
    }
    return sum;
  }

  // out_i = f'(p_i) = p_i + a p_i^3/3.
  template <class S>
  void grad_T(nonsep::sdk::Vector<S> p, std::span<S> out) const {
    for (std::size_t i = 0; i < p.size(); ++i) out[i] = p[i] + a / 3.0 * p[i] * p[i] * p[i];
  }
  // out_i = q_i + W'(q_i - q_{i-1}) - W'(q_{i+1} - q_i), W'(r) = k r + b r^3; the two ends wrap around.
  template <class S>
  void grad_V(nonsep::sdk::Vector<S> q, std::span<S> out) const {
    const std::size_t n = q.size();
    out[0] = q[0] + bond_force(q[0] - q[n - 1]) - bond_force(q[1] - q[0]);
    for (std::size_t i = 1; i + 1 < n; ++i) out[i] = q[i] + bond_force(q[i] - q[i - 1]) - bond_force(q[i + 1] - q[i]);
    out[n - 1] = q[n - 1] + bond_force(q[n - 1] - q[n - 2]) - bond_force(q[0] - q[n - 1]);
  }

  // Hessian-vector products, the energy's and the tangent map's cost: two passes over the sites, no dual numbers.
  // out_i = f''(p_i) v_i, f''(p) = 1 + a p^2.
  void hvp_T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    for (std::size_t i = 0; i < p.size(); ++i) out[i] = (1.0 + a * p[i] * p[i]) * v[i];
  }
  // out_i = v_i + W''(q_i - q_{i-1}) (v_i - v_{i-1}) - W''(q_{i+1} - q_i) (v_{i+1} - v_i), the ends wrapping around.
  // Each bond is computed twice, once per site it joins: that vectorizes; carrying it from one site to the next does
  // not (measured: 2.0x-2.2x a gradient instead of 1.1x-1.5x for n = 100 .. 10^5).
  void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const {
    const std::size_t n = q.size();
    const auto bond = [&](std::size_t i, std::size_t j) { return bond_stiffness(q[j] - q[i]) * (v[j] - v[i]); };
    out[0] = v[0] + bond(n - 1, 0) - bond(0, 1);
    for (std::size_t i = 1; i + 1 < n; ++i) out[i] = v[i] + bond(i - 1, i) - bond(i, i + 1);
    out[n - 1] = v[n - 1] + bond(n - 2, n - 1) - bond(n - 1, 0);
  }

  // The product term of H written out, one pass over the sites (plugin_abi.h energy_TTV, energy_VVT): with
  // t = f'(p) and the tridiagonal V'' met as its bonds,
  //   H_TTV = sum_i [t_i^2 + W''(q_{i+1} - q_i) (t_{i+1} - t_i)^2],   H_VVT = sum_i f''(p_i) (grad V)_i^2.
  // Through the products H costs a gradient, a product and a pass for their dot product; this, about a gradient.
  double energy_TTV(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> p) const {
    return periodic_sum(q.size(), [&](std::size_t, std::size_t i, std::size_t next) {
      const double ti = kinetic_slope(p[i]), step = kinetic_slope(p[next]) - ti;
      return ti * ti + bond_stiffness(q[next] - q[i]) * step * step;
    });
  }
  double energy_VVT(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> p) const {
    return periodic_sum(q.size(), [&](std::size_t previous, std::size_t i, std::size_t next) {
      const double g = q[i] + bond_force(q[i] - q[previous]) - bond_force(q[next] - q[i]);
      return (1.0 + a * p[i] * p[i]) * g * g;
    });
  }

  double a, k, b;

 private:
  double kinetic_slope(double p) const { return p + a / 3.0 * p * p * p; }
  double bond_stiffness(double r) const { return k + 3.0 * b * r * r; }
  // sum_i term(i - 1, i, i + 1) over the n >= 3 sites, the ends wrapping around; four partial sums, so that the
  // additions do not wait on one another.
  template <class Term>
  static double periodic_sum(std::size_t n, const Term& term) {
    double partial[4] = {0.0, 0.0, 0.0, 0.0};
    double sum = term(n - 1, 0, 1) + term(n - 2, n - 1, 0);
    std::size_t i = 1;
    for (; i + 4 < n; i += 4)
      for (std::size_t j = 0; j < 4; ++j) partial[j] += term(i + j - 1, i + j, i + j + 1);
    for (; i + 1 < n; ++i) sum += term(i - 1, i, i + 1);
    return sum + ((partial[0] + partial[1]) + (partial[2] + partial[3]));
  }
  template <class S>
  S bond_force(const S& r) const {
    return (k + b * r * r) * r;
  }
};

// The shipped plugin: up to 2^20 sites.
using LatticeChain = LatticeChainModel<std::size_t{1} << 20>;
