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
// Solving the linear stages: fixed-point iteration dZ^{m+1}_i = dt sum_j a_ij J(Y_j) (dz + dZ^m_j) from dZ^0 = 0,
// with the stages' own stopping rule (gauss_legendre.hpp) per tangent vector: relative change
// max |dZ^{m+1} - dZ^m| / max(|dz|_inf, |dZ^{m+1}|_inf) at one ulp, or stalled at round-off (<= 64 ulp and not
// decreasing); dz' then takes the products of the last iteration. It contracts at the rate of the stages' iteration
// (dt |J| |A|), so it takes about as many iterations as the step did, each one hvp_H per stage and vector: O(n) per
// vector for a sparse model. A linear solve would form J(Y_i) (2n products per stage) and factor a 2ns x 2ns
// matrix: cheaper only for k close to 2n on small n; the iteration is chosen for every k (one code path, O(k n)
// memory per state). Converged to round-off, the map is symplectic (M^T J M = J) to round-off as the step is.
//
// The states are stepped by GaussLegendre::step, bit for bit as the plain scheme steps them; each tangent vector's
// numbers depend only on its state and itself (batch equals single). Layout of the tangent vectors: that of
// tangent_basic_step.hpp (vector j of state b at entry b*k + j, dq in q(), dp in p()).
//
// Errors: InvalidArgument for tangents that do not fit x, or a model without hvp_H (require_hamiltonian_hessian);
// ModelError from the step (its states that failed), or naming the states whose tangent iteration failed (not
// finite, or no convergence in max_iterations); the model's exceptions propagate. The tangents are then unspecified.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"

namespace nonsep {

class TangentGaussLegendre {
 public:
  explicit TangentGaussLegendre(GaussLegendre base = GaussLegendre()) : base_(std::move(base)) {}

  const GaussLegendre& base() const { return base_; }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  // hvp_H: s per tangent vector per iteration.
  const HessianCounts& hessian_evaluations() const { return hessians_; }
  // Iterations of the linear stages each tangent vector of the last step took (vector j of state b at b*k + j).
  std::span<const int> tangent_iterations() const { return iterations_; }

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
  // Work arrays of the rows (tangent vectors) still iterating, stage-major: stage i, row a of active_, component c
  // at (i*A + a)*n + c (A = active_.size()); dZ per row and stage at (i*R + r)*n + c (R = all rows).
  template <class M>
  void map_tangents(const M& model, const PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::size_t k, double dt) {
    const GaussLegendreTableau& tableau = base_.tableau();
    const std::size_t s = static_cast<std::size_t>(tableau.stages), n = x.dimension(), size = x.size();
    const std::size_t rows = tangents.count();
    const std::span<const double> stage_q = base_.stage_points_q(), stage_p = base_.stage_points_p();
    for (auto* v : {&dZ_q_, &dZ_p_}) v->assign(s * rows * n, 0.0);
    iterations_.assign(rows, 0);
    last_change_.assign(rows, std::numeric_limits<double>::infinity());
    active_.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) active_[r] = r;
    const double eps = std::numeric_limits<double>::epsilon();
    std::vector<std::size_t> failed;
    for (int m = 0; m < base_.max_iterations() && !active_.empty(); ++m) {
      const std::size_t count = active_.size(), points = s * count;
      for (auto* v : {&point_q_, &point_p_, &direction_q_, &direction_p_, &product_q_, &product_p_})
        v->resize(points * n);
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
        ++iterations_[r];
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
    if (!failed.empty()) throw ModelError(failure_message(failed, k, x.count()));
  }

  std::string failure_message(std::vector<std::size_t> failed, std::size_t k, std::size_t count) const {
    std::sort(failed.begin(), failed.end());
    std::string message = "the tangent map of Gauss-Legendre collocation (order " + std::to_string(base_.order()) +
                          "): the iteration of the linear stages did not converge in " +
                          std::to_string(base_.max_iterations()) + " iterations, or an iterate is not finite, for";
    for (std::size_t i = 0; i < failed.size(); ++i)
      message += (i ? ", " : " ") + std::string("vector ") + std::to_string(failed[i] % k) +
                 (count > 1 ? " of state " + std::to_string(failed[i] / k) : std::string());
    return message + "; a smaller dt makes it contract";
  }

  GaussLegendre base_;
  HessianCounts hessians_;
  std::vector<double> dZ_q_, dZ_p_, next_q_, next_p_;
  std::vector<double> point_q_, point_p_, direction_q_, direction_p_, product_q_, product_p_;
  std::vector<int> iterations_;
  std::vector<double> last_change_;
  std::vector<std::size_t> active_, still_;
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them.
inline TangentGaussLegendre tangent_map_of(const GaussLegendre& stepper, std::size_t) {
  return TangentGaussLegendre(stepper);
}

}  // namespace nonsep
