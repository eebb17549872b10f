#pragma once
// Jacobians of maps of phase space by central differences (support/finite_difference.hpp), and the symplectic
// defect of a Jacobian, for the symplecticity and tangent-map tests. Phase space is ordered (q_0 .. q_n-1,
// p_0 .. p_n-1); a map takes and returns 2n numbers.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "nonsep/core/base/phase_space_batch.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "support/finite_difference.hpp"

namespace nonsep::testing {

// The Jacobian d map(z) / dz by central differences with step h in every variable. `map` takes and returns a
// std::vector<double> of the same size as z.
template <class Map>
Eigen::MatrixXd jacobian_by_differences(const Map& map, const std::vector<double>& z, double h) {
  const auto size = static_cast<Eigen::Index>(z.size());
  Eigen::MatrixXd jacobian(size, size);
  for (Eigen::Index k = 0; k < size; ++k) {
    const std::vector<double> column = central_difference_along(map, z, static_cast<std::size_t>(k), h);
    for (Eigen::Index i = 0; i < size; ++i) jacobian(i, k) = column[static_cast<std::size_t>(i)];
  }
  return jacobian;
}

// Omega = [[0, I], [-I, 0]] of size 2n.
inline Eigen::MatrixXd symplectic_form(Eigen::Index n) {
  Eigen::MatrixXd omega = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  omega.topRightCorner(n, n).setIdentity();
  omega.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  return omega;
}

// max |J^T Omega J - Omega|, divided by max(1, max |J|^2) when `relative`: zero for a symplectic J (up to the
// differencing error for a Jacobian by differences, ~1e-9 with h = 1e-6); NaN when J is not finite, so that every
// comparison a test makes with it fails.
inline double symplecticity_defect(const Eigen::MatrixXd& jacobian, bool relative = false) {
  if (!jacobian.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::MatrixXd omega = symplectic_form(jacobian.rows() / 2);
  const double largest = jacobian.cwiseAbs().maxCoeff();
  const double scale = relative ? std::max(1.0, largest * largest) : 1.0;
  return (jacobian.transpose() * omega * jacobian - omega).cwiseAbs().maxCoeff() / scale;
}

// A single state as 2n numbers (q then p), and back.
inline std::vector<double> phase_point(const PhaseSpaceBatch& x) {
  std::vector<double> z(x.q().begin(), x.q().end());
  z.insert(z.end(), x.p().begin(), x.p().end());
  return z;
}
inline PhaseSpaceBatch phase_state(const std::vector<double>& z) {
  const std::size_t n = z.size() / 2;
  PhaseSpaceBatch x(n, 1);
  std::copy_n(z.begin(), n, x.q().begin());
  std::copy_n(z.begin() + static_cast<std::ptrdiff_t>(n), n, x.p().begin());
  return x;
}

// The map of `steps` steps of dt of a fresh Integrator(spec), on one state.
template <class M>
auto integrator_map(const M& model, const IntegratorSpec& spec, double dt, int steps = 1) {
  return [&model, spec, dt, steps](const std::vector<double>& z) {
    PhaseSpaceBatch x = phase_state(z);
    Integrator integrator(spec);
    for (int s = 0; s < steps; ++s) integrator.step(model, x, dt);
    return phase_point(x);
  };
}

// 2n tangent vectors forming the identity: after stepping, vector j is column j of the Jacobian M.
inline PhaseSpaceBatch identity_tangents(std::size_t n) {
  PhaseSpaceBatch t(n, 2 * n);
  for (std::size_t j = 0; j < n; ++j) {
    t.q(j)[j] = 1.0;
    t.p(n + j)[j] = 1.0;
  }
  return t;
}

inline Eigen::MatrixXd as_matrix(const PhaseSpaceBatch& tangents) {
  const auto n = static_cast<Eigen::Index>(tangents.dimension());
  Eigen::MatrixXd m(2 * n, 2 * n);
  for (Eigen::Index j = 0; j < 2 * n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) {
      m(i, j) = tangents.q(static_cast<std::size_t>(j))[static_cast<std::size_t>(i)];
      m(n + i, j) = tangents.p(static_cast<std::size_t>(j))[static_cast<std::size_t>(i)];
    }
  return m;
}

}  // namespace nonsep::testing
