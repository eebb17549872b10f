#pragma once
// The tangent map of Gauss-Legendre collocation (gauss_legendre.hpp; s = 1 is the implicit midpoint rule): the exact
// derivative of the discrete map, applied to k tangent vectors per state alongside the step itself
// (Hairer, Lubich, Wanner, Geometric Numerical Integration, VI.4: the derivative of a Runge-Kutta map is the same
// method applied to the variational equation). With f = (dH/dp, -dH/dq), J(z) = Df(z) and the stage points
// Y_i = z + Z_i of the step,
//   z' = z + dt sum_i b_i f(Y_i),   Z_i = dt sum_j a_ij f(Y_j)
// differentiate to
//   dz' = dz + dt sum_i b_i J(Y_i) (dz + dZ_i),   dZ_i = dt sum_j a_ij J(Y_j) (dz + dZ_j),
// linear stage equations in dZ with the step's own stage points. J(Y) v is the directional derivative of grad H
// (hamiltonian_gradient.hpp, ModelWithHamiltonianHessian; the plugin entry hvp_H), one batched call per iteration
// for every tangent vector still iterating.
//
// Solving the linear stages, one of two ways chosen by n, k and s alone (solves_directly), so that every state of a
// run takes the same path whatever its batch:
// - directly (gauss_linear_stages.hpp): J(Y_i) formed from 2n products per stage point (hvp_H along each unit
//   vector), then one LU of the 2ns x 2ns system per state, solved for its k vectors together, a few states at once
//   (their operations interleaved). Costs s 2n products per state whatever k, plus the LU.
// - by fixed-point iteration dZ^{m+1}_i = dt sum_j a_ij J(Y_j) (dz + dZ^m_j) from dZ^0 = 0, with the stages' own
//   stopping rule (gauss_legendre.hpp) per tangent vector: relative change
//   max |dZ^{m+1} - dZ^m| / max(|dz|_inf, |dZ^{m+1}|_inf) at one ulp, or stalled at round-off (<= 64 ulp and not
//   decreasing); dz' then takes the products of the last iteration. It contracts at the rate of the stages'
//   iteration (dt |J| |A|), so it takes about as many iterations as the step did (5 to 10): s k products per
//   iteration, O(n) per vector for a sparse model, O(k n) memory per state.
// The direct solve is taken when 2n <= 4k (its products cost at most what 4 iterations of the k vectors cost) and
// 2ns <= 32 (the LU stays under about 11000 flops): paper1d, paper2d and Henon-Heiles with one vector, any model of
// up to 2 degrees of freedom per vector with several. Both give the map's exact derivative to round-off, and it is
// symplectic (M^T J M = J) to round-off as the step is.
//
// The states are stepped by GaussLegendre::step, bit for bit as the plain scheme steps them; each tangent vector's
// numbers depend only on its state and itself (batch equals single). Layout of the tangent vectors: that of
// tangent_basic_step.hpp (vector j of state b at entry b*k + j, dq in q(), dp in p()).
//
// Errors: InvalidArgument for tangents that do not fit x, or a model without hvp_H (require_hamiltonian_hessian);
// ModelError from the step (its states that failed), or naming the states whose tangent vectors failed (not finite,
// or no convergence in max_iterations); the model's exceptions propagate. The tangents are then unspecified.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/tangent/gauss_linear_stages.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"

namespace nonsep {

class TangentGaussLegendre {
 public:
  explicit TangentGaussLegendre(GaussLegendre base = GaussLegendre()) : base_(std::move(base)) {}

  const GaussLegendre& base() const { return base_; }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  // hvp_H: s 2n per state solved directly, s per tangent vector and iteration otherwise.
  const HessianCounts& hessian_evaluations() const { return hessians_; }
  // Whether the linear stages of n degrees of freedom, k vectors per state and s stages are solved directly (above).
  static bool solves_directly(std::size_t n, std::size_t k, int s) {
    return 2 * n <= 4 * k && 2 * n * static_cast<std::size_t>(s) <= 32;
  }

  // Advances x by dt as GaussLegendre::step does and maps the tangent vectors by the step's derivative. Errors above.
  template <class M>
  requires ModelWithHamiltonianHessian<M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    const std::size_t k = check_tangents_fit(x, tangents);
    require_hamiltonian_hessian(model, base_.stages() == 1 ? "implicit_midpoint" : "gauss");
    base_.step(model, x, dt);
    map_tangents(model, x, tangents, k, dt);
  }

  // The private state is the plain stepper's (its starting values, gauss_legendre.hpp); the vectors keep none.
  template <class M>
  requires ModelWithHamiltonianHessian<M>
  void step_part(const M& model, PhaseSpaceBatch& part, PhaseSpaceBatch& part_tangents,
                 const TangentGaussLegendre& before, std::size_t first, std::size_t total, double dt) {
    const std::size_t k = check_tangents_fit(part, part_tangents);
    require_hamiltonian_hessian(model, base_.stages() == 1 ? "implicit_midpoint" : "gauss");
    base_.step_part(model, part, before.base_, first, total, dt);
    map_tangents(model, part, part_tangents, k, dt);
  }
  void compact(const std::vector<bool>& retire) { base_.compact(retire); }
  SchemeState save_state(const PhaseSpaceBatch& states) const { return base_.save_state(states); }
  void restore_state(const SchemeState& state) { base_.restore_state(state); }
  std::vector<SchemeFigure> report() const { return base_.report(); }

 private:
  template <class M>
  void map_tangents(const M& model, const PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::size_t k, double dt) {
    if (solves_directly(x.dimension(), k, base_.stages()))
      map_tangents_directly(model, x, tangents, k, dt);
    else
      map_tangents_by_iteration(model, x, tangents, k, dt);
  }

  // body(dimension) with the dimension n as a compile-time constant for 1 to 3 degrees of freedom (the loops over a
  // state's components then unroll), else as it is.
  template <class Body>
  static void with_dimension(std::size_t n, const Body& body) {
    if (n == 1)
      body(std::integral_constant<std::size_t, 1>{});
    else if (n == 2)
      body(std::integral_constant<std::size_t, 2>{});
    else if (n == 3)
      body(std::integral_constant<std::size_t, 3>{});
    else
      body(n);
  }

  // Stage point i of state b along unit direction e (e < n: dq_e, else dp_{e-n}) at point ((i*B + b)*2n + e), B the
  // states; the point's components at that index times n. J(Y_i) of state b goes column-major into jacobians_.
  template <class M>
  void map_tangents_directly(const M& model, const PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::size_t k,
                             double dt) {
    const GaussLegendreTableau& tableau = base_.tableau();
    const std::size_t s = static_cast<std::size_t>(tableau.stages), n = x.dimension(), d = 2 * n;
    const std::size_t states = x.count(), size = x.size(), points = s * states * d;
    const std::span<const double> stage_q = base_.stage_points_q(), stage_p = base_.stage_points_p();
    for (auto* v : {&point_q_, &point_p_, &product_q_, &product_p_}) v->resize(points * n);
    if (units_for_ != std::pair{points, n}) {  // the unit directions, kept between steps of the same sizes
      units_for_ = {};
      for (auto* v : {&direction_q_, &direction_p_}) v->assign(points * n, 0.0);
      for (std::size_t point = 0; point < points; ++point) {
        const std::size_t e = point % d;
        (e < n ? direction_q_[point * n + e] : direction_p_[point * n + e - n]) = 1.0;
      }
      units_for_ = {points, n};
    }
    with_dimension(n, [&](auto dimension) {
      const std::size_t n = dimension;  // known at compile time for 1 to 3 degrees of freedom
      for (std::size_t i = 0; i < s; ++i)
        for (std::size_t b = 0; b < states; ++b) {
          const double* from_q = stage_q.data() + i * size + b * n;
          const double* from_p = stage_p.data() + i * size + b * n;
          for (std::size_t e = 0; e < d; ++e) {
            const std::size_t to = ((i * states + b) * d + e) * n;
            for (std::size_t c = 0; c < n; ++c) {
              point_q_[to + c] = from_q[c];
              point_p_[to + c] = from_p[c];
            }
          }
        }
    });
    model.hvp_H(base_.form(), point_q_, point_p_, direction_q_, direction_p_, product_q_, product_p_, points);
    hessians_.hvp_H += points;
    // The states in groups of linear_stage_lanes, solved together (each bit for bit as alone).
    jacobians_.resize(linear_stage_lanes * s * d * d);
    vectors_.resize(linear_stage_lanes * k * d);
    std::vector<std::size_t> failed;
    with_dimension(n, [&](auto dimension) {
      const std::size_t n = dimension, d = 2 * n;
      for (std::size_t first = 0; first < states; first += linear_stage_lanes) {
        const std::size_t group = std::min(linear_stage_lanes, states - first);
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t b = first + g;
          // Column e of J(Y_i) = (d(dH/dp), -d(dH/dq)) along e.
          for (std::size_t i = 0; i < s; ++i)
            for (std::size_t e = 0; e < d; ++e) {
              const std::size_t from = ((i * states + b) * d + e) * n, to = ((g * s + i) * d + e) * d;
              for (std::size_t c = 0; c < n; ++c) {
                jacobians_[to + c] = product_p_[from + c];
                jacobians_[to + n + c] = -product_q_[from + c];
              }
            }
          for (std::size_t j = 0; j < k; ++j)
            for (std::size_t c = 0; c < n; ++c) {
              vectors_[(g * k + j) * d + c] = tangents.q()[(b * k + j) * n + c];
              vectors_[(g * k + j) * d + n + c] = tangents.p()[(b * k + j) * n + c];
            }
        }
        const unsigned not_finite = map_by_linear_stages(tableau, dt, jacobians_, d, vectors_, k, group);
        for (std::size_t g = 0; g < group; ++g) {
          const std::size_t b = first + g;
          if (not_finite & (1u << g)) {
            for (std::size_t j = 0; j < k; ++j) failed.push_back(b * k + j);
            continue;
          }
          for (std::size_t j = 0; j < k; ++j)
            for (std::size_t c = 0; c < n; ++c) {
              tangents.q()[(b * k + j) * n + c] = vectors_[(g * k + j) * d + c];
              tangents.p()[(b * k + j) * n + c] = vectors_[(g * k + j) * d + n + c];
            }
        }
      }
    });
    if (!failed.empty())
      throw ModelError(failure_message(failed, k, states, "the linear stages are singular or not finite"));
  }

  // Work arrays of the rows (tangent vectors) still iterating, stage-major: stage i, row a of active_, component c
  // at (i*A + a)*n + c (A = active_.size()); dZ per row and stage at (i*R + r)*n + c (R = all rows).
  template <class M>
  void map_tangents_by_iteration(const M& model, const PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::size_t k,
                                 double dt) {
    const GaussLegendreTableau& tableau = base_.tableau();
    const std::size_t s = static_cast<std::size_t>(tableau.stages), n = x.dimension(), size = x.size();
    const std::size_t rows = tangents.count();
    const std::span<const double> stage_q = base_.stage_points_q(), stage_p = base_.stage_points_p();
    for (auto* v : {&dZ_q_, &dZ_p_}) v->assign(s * rows * n, 0.0);
    last_change_.assign(rows, std::numeric_limits<double>::infinity());
    active_.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) active_[r] = r;
    const double eps = std::numeric_limits<double>::epsilon();
    std::vector<std::size_t> failed;
    for (int m = 0; m < base_.max_iterations() && !active_.empty(); ++m) {
      const std::size_t count = active_.size(), points = s * count;
      for (auto* v : {&point_q_, &point_p_, &direction_q_, &direction_p_, &product_q_, &product_p_})
        v->resize(points * n);
      units_for_ = {};
      for (std::size_t i = 0; i < s; ++i)
        for (std::size_t a = 0; a < count; ++a) {
          const std::size_t r = active_[a], b = r / k, to = (i * count + a) * n, z = (i * rows + r) * n;
          for (std::size_t c = 0; c < n; ++c) {
            point_q_[to + c] = stage_q[i * size + b * n + c];
            point_p_[to + c] = stage_p[i * size + b * n + c];
            direction_q_[to + c] = tangents.q()[r * n + c] + dZ_q_[z + c];
            direction_p_[to + c] = tangents.p()[r * n + c] + dZ_p_[z + c];
          }
        }
      model.hvp_H(base_.form(), point_q_, point_p_, direction_q_, direction_p_, product_q_, product_p_, points);
      hessians_.hvp_H += points;
      still_.clear();
      for (std::size_t a = 0; a < count; ++a) {
        const std::size_t r = active_[a];
        // dZ^{m+1}_i = dt sum_j a_ij (d(dH/dp)_j, -d(dH/dq)_j); change and size as the stages measure them.
        double change = 0.0, scale = 0.0, probe = 0.0;
        for (std::size_t c = 0; c < n; ++c)
          scale = std::max({scale, std::abs(tangents.q()[r * n + c]), std::abs(tangents.p()[r * n + c])});
        next_q_.resize(s * n);
        next_p_.resize(s * n);
        for (std::size_t i = 0; i < s; ++i)
          for (std::size_t c = 0; c < n; ++c) {
            double sum_q = 0.0, sum_p = 0.0;
            for (std::size_t j = 0; j < s; ++j) {
              const std::size_t at = (j * count + a) * n + c;
              sum_q += tableau.a[i * s + j] * product_p_[at];
              sum_p += tableau.a[i * s + j] * -product_q_[at];
            }
            sum_q *= dt;
            sum_p *= dt;
            const std::size_t z = (i * rows + r) * n + c;
            change = std::max({change, std::abs(sum_q - dZ_q_[z]), std::abs(sum_p - dZ_p_[z])});
            scale = std::max({scale, std::abs(sum_q), std::abs(sum_p)});
            probe += 0.0 * sum_q + 0.0 * sum_p;
            next_q_[i * n + c] = sum_q;
            next_p_[i * n + c] = sum_p;
          }
        const double relative = scale > 0.0 ? change / scale : 0.0;
        const bool finite = probe == 0.0;
        const bool converged = relative <= eps || (relative >= last_change_[r] && relative <= 64 * eps);
        if (!finite) {
          failed.push_back(r);
        } else if (converged) {
          // dz' = dz + dt sum_i b_i J(Y_i) (dz + dZ^m_i), with this iteration's products.
          for (std::size_t c = 0; c < n; ++c) {
            double sum_q = 0.0, sum_p = 0.0;
            for (std::size_t i = 0; i < s; ++i) {
              sum_q += tableau.b[i] * product_p_[(i * count + a) * n + c];
              sum_p += tableau.b[i] * -product_q_[(i * count + a) * n + c];
            }
            tangents.q()[r * n + c] += dt * sum_q;
            tangents.p()[r * n + c] += dt * sum_p;
          }
        } else {
          for (std::size_t i = 0; i < s; ++i)
            for (std::size_t c = 0; c < n; ++c) {
              dZ_q_[(i * rows + r) * n + c] = next_q_[i * n + c];
              dZ_p_[(i * rows + r) * n + c] = next_p_[i * n + c];
            }
          last_change_[r] = relative;
          still_.push_back(r);
        }
      }
      active_.swap(still_);
    }
    failed.insert(failed.end(), active_.begin(), active_.end());
    if (!failed.empty())
      throw ModelError(failure_message(failed, k, x.count(),
                                       "the iteration of the linear stages did not converge in " +
                                           std::to_string(base_.max_iterations()) +
                                           " iterations, or an iterate is not finite"));
  }

  std::string failure_message(std::vector<std::size_t> failed, std::size_t k, std::size_t count,
                              const std::string& what) const {
    std::sort(failed.begin(), failed.end());
    std::string message = "the tangent map of Gauss-Legendre collocation (order " + std::to_string(base_.order()) +
                          "): " + what + ", for";
    for (std::size_t i = 0; i < failed.size(); ++i)
      message += (i ? ", " : " ") + std::string("vector ") + std::to_string(failed[i] % k) +
                 (count > 1 ? " of state " + std::to_string(failed[i] / k) : std::string());
    return message + "; a smaller dt makes it contract";
  }

  GaussLegendre base_;
  HessianCounts hessians_;
  std::vector<double> dZ_q_, dZ_p_, next_q_, next_p_;
  std::vector<double> point_q_, point_p_, direction_q_, direction_p_, product_q_, product_p_;
  std::vector<double> jacobians_, vectors_;
  // The points and dimension whose unit directions direction_q_, direction_p_ hold for the direct solve ({0, 0}: none).
  std::pair<std::size_t, std::size_t> units_for_{};
  std::vector<double> last_change_;
  std::vector<std::size_t> active_, still_;
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them.
inline TangentGaussLegendre tangent_map_of(const GaussLegendre& stepper, std::size_t) {
  return TangentGaussLegendre(stepper);
}

}  // namespace nonsep
