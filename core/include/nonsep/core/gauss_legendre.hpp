#pragma once
// Gauss-Legendre collocation with s = 1, 2, 3 stages (orders 2, 4, 6), a comparator for Chin's explicit schemes:
// the implicit Runge-Kutta method applied to Hamilton's equations of the solved Hamiltonian itself,
//   z = (q, p),   dz/dt = f(z) = (dH/dp, -dH/dq)   (H_TTV or H_VVT, hamiltonian_gradient.hpp),
//   Z_i = dt sum_j a_ij f(z + Z_j),   z' = z + dt sum_i b_i f(z + Z_i),   i, j = 1..s.
// s = 1 is the implicit midpoint rule, z' = z + dt f((z + z')/2); there is no separate implicit_midpoint header.
// Symplectic and symmetric (time-reversible: the step of -dt undoes the step of dt) for any s, as collocation at
// the Gauss points (Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3 and VI.4); both hold up to
// the round-off the iteration below leaves.
//
// Solving the stages: fixed-point iteration Z^{m+1}_i = dt sum_j a_ij f(z + Z^m_j) from Z^0 = 0, the whole batch
// together: each iteration evaluates f at the s stages of every state still iterating, in one batched call of
// s x (states) points. Stopping rule, per state, with delta_m = max_k |Z^{m+1}_k - Z^m_k| / max(|z|_inf, |Z^{m+1}|_inf)
// (the change relative to the state's size):
//   converged  when delta_m <= eps (one ulp of the state's largest component: nothing left to gain), or when
//              delta_m >= delta_{m-1} and delta_m <= 64 eps (the change stopped decreasing at round-off, GNI VIII.6);
//   failed     when an iterate is not finite, or after max_iterations iterations without converging.
// A converged state takes z' = z + dt sum_i b_i f(z + Z^m_i) with the evaluations of its last iteration, so a step
// costs s grad H per state per iteration and nothing more. A state that has converged stops iterating; the others
// go on. Each state's numbers therefore do not depend on the other states of the batch (batch equals single,
// bit for bit, as long as the model's per-state results do not). The iteration contracts when dt times the
// Lipschitz constant of f is small (about dt |Hess H| < 1); larger steps fail. Starting from the previous step's
// stages extrapolated (GNI VIII.6.1) would save iterations; Z^0 = 0 keeps each step independent of the last.
//
// Failures: step() throws nonsep::ModelError naming every state that failed (its index in the batch, omitted for a
// batch of one) and why, after advancing the states that converged and leaving the failed ones at their starting
// point. This fits the host's failure model: a ModelError from a batch makes it redo the step state by state and
// retire only the states that throw. try_step() returns the failures instead of throwing. Exceptions of the model
// propagate; the batch is then unspecified (some states may have advanced).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/core/comparator_description.hpp"
#include "nonsep/core/hamiltonian_gradient.hpp"

namespace nonsep {

// The Butcher tableau of the s-stage Gauss-Legendre method (s = 1, 2, 3): a row-major s x s, b, c.
struct GaussLegendreTableau {
  int stages;
  std::vector<double> a, b, c;

  // Throws InvalidArgument unless stages is 1, 2 or 3.
  static GaussLegendreTableau for_stages(int stages) {
    const double r3 = std::sqrt(3.0), r15 = std::sqrt(15.0);
    switch (stages) {
      case 1:
        return {1, {0.5}, {1.0}, {0.5}};
      case 2:
        return {2, {0.25, 0.25 - r3 / 6.0, 0.25 + r3 / 6.0, 0.25}, {0.5, 0.5}, {0.5 - r3 / 6.0, 0.5 + r3 / 6.0}};
      case 3:
        return {3,
                {5.0 / 36.0, 2.0 / 9.0 - r15 / 15.0, 5.0 / 36.0 - r15 / 30.0,   //
                 5.0 / 36.0 + r15 / 24.0, 2.0 / 9.0, 5.0 / 36.0 - r15 / 24.0,   //
                 5.0 / 36.0 + r15 / 30.0, 2.0 / 9.0 + r15 / 15.0, 5.0 / 36.0},  //
                {5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0},
                {0.5 - r15 / 10.0, 0.5, 0.5 + r15 / 10.0}};
      default:
        throw InvalidArgument("Gauss-Legendre collocation has 1, 2 or 3 stages (orders 2, 4, 6); found " +
                              std::to_string(stages) + " stages");
    }
  }
};

// A state whose step failed: its index in the batch and why.
struct StateFailure {
  std::size_t state = 0;
  std::string reason;
};

class GaussLegendre {
 public:
  static constexpr int default_max_iterations = 100;

  // Order 2, 4 or 6 (s = order/2 stages). Throws InvalidArgument on another order or max_iterations < 1.
  explicit GaussLegendre(HamiltonianForm form = HamiltonianForm::TTV, int order = 2,
                         int max_iterations = default_max_iterations)
      : tableau_(GaussLegendreTableau::for_stages(order % 2 == 0 ? order / 2 : 0)),
        gradient_(form),
        max_iterations_(max_iterations) {
    if (max_iterations < 1)
      throw InvalidArgument("the fixed-point iteration needs max_iterations >= 1 (found " +
                            std::to_string(max_iterations) + ")");
  }

  HamiltonianForm form() const { return gradient_.form(); }
  int order() const { return 2 * tableau_.stages; }
  int stages() const { return tableau_.stages; }
  int max_iterations() const { return max_iterations_; }
  const GaussLegendreTableau& tableau() const { return tableau_; }
  // grad_H: s per state per iteration.
  const EvaluationCounts& evaluations() const { return gradient_.evaluations(); }
  void add_evaluations(const EvaluationCounts& counts) { gradient_.add_evaluations(counts); }
  // Iterations each state of the last step took (failed states: the iterations tried).
  std::span<const int> iterations() const { return iterations_; }

  ComparatorDescription describe() const {
    ComparatorDescription d;
    d.scheme = "gauss";
    d.method = "Gauss-Legendre collocation, " + std::to_string(stages()) + " stage" + (stages() > 1 ? "s" : "") +
               (stages() == 1 ? " (implicit midpoint rule)" : "");
    d.reference = "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VI.4, VIII.6";
    d.order = order();
    d.properties = "symplectic and symmetric on (q, p), up to the round-off the fixed-point iteration leaves";
    d.grad_H_per_iteration = static_cast<std::uint64_t>(stages());
    d.cost = std::to_string(stages()) +
             " grad H per state per fixed-point iteration; iterations run from Z = 0 "
             "until the stages stop changing (at most " +
             std::to_string(max_iterations_) + ")";
    d.parameters = {{"max_iterations", static_cast<double>(max_iterations_)}};
    return d;
  }

  // Advances every state of x by dt (finite, non-zero). Throws InvalidArgument on a bad dt or a batch whose
  // dimension differs from the model's, ModelError naming the states whose iteration failed (see above);
  // propagates the model's exceptions.
  template <ModelWithThirdDerivatives M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    const auto failures = try_step(model, x, dt);
    if (failures.empty()) return;
    std::string message = "Gauss-Legendre collocation (order " + std::to_string(order()) +
                          ", dt = " + std::to_string(dt) + "): the fixed-point iteration failed";
    if (x.count() == 1) {
      message += " (" + failures[0].reason + ")";
    } else {
      message += " for ";
      for (std::size_t i = 0; i < failures.size(); ++i)
        message += (i ? "; " : "") + std::string("state ") + std::to_string(failures[i].state) + " of " +
                   std::to_string(x.count()) + " (" + failures[i].reason + ")";
    }
    throw ModelError(message + "; a smaller dt makes the iteration contract");
  }

  // As step(), but returns the failed states instead of throwing ModelError; they keep their starting point.
  template <ModelWithThirdDerivatives M>
  std::vector<StateFailure> try_step(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    const std::size_t count = x.count(), n = x.dimension(), s = static_cast<std::size_t>(tableau_.stages);
    const std::size_t w = 2 * n;  // one stage of one state: (q, p)
    // Per state b: Z at stages_[(b*s + i)*w ...], f(z + Z) at slopes_ (same layout).
    stages_.assign(count * s * w, 0.0);
    slopes_.resize(count * s * w);
    iterations_.assign(count, 0);
    last_change_.assign(count, std::numeric_limits<double>::infinity());
    active_.resize(count);
    for (std::size_t b = 0; b < count; ++b) active_[b] = b;
    std::vector<StateFailure> failures;
    const double eps = std::numeric_limits<double>::epsilon();
    const double* a = tableau_.a.data();
    for (int m = 0; m < max_iterations_ && !active_.empty(); ++m) {
      evaluate_slopes(model, x, active_);
      still_.clear();
      for (std::size_t b : active_) {
        ++iterations_[b];
        const double* q = x.q().data() + b * n;
        const double* p = x.p().data() + b * n;
        const double* f = slopes_.data() + b * s * w;
        double* z = stages_.data() + b * s * w;
        double change = 0.0, scale = 0.0;
        bool finite = true;
        for (std::size_t k = 0; k < n; ++k) scale = std::max(scale, std::max(std::abs(q[k]), std::abs(p[k])));
        for (std::size_t i = 0; i < s; ++i)
          for (std::size_t k = 0; k < w; ++k) {
            double sum = 0.0;
            for (std::size_t j = 0; j < s; ++j) sum += a[i * s + j] * f[j * w + k];
            sum *= dt;
            finite &= std::isfinite(sum);
            change = std::max(change, std::abs(sum - z[i * w + k]));
            scale = std::max(scale, std::abs(sum));
            z[i * w + k] = sum;
          }
        if (!finite) {
          failures.push_back({b, "an iterate is not finite after " + std::to_string(iterations_[b]) + " iterations"});
          continue;
        }
        const double relative = scale > 0.0 ? change / scale : 0.0;
        const bool converged = relative <= eps || (relative >= last_change_[b] && relative <= 64 * eps);
        last_change_[b] = relative;
        if (converged)
          advance(x, b, dt);
        else
          still_.push_back(b);
      }
      active_.swap(still_);
    }
    for (std::size_t b : active_) {
      char change[32];
      std::snprintf(change, sizeof change, "%.3g", last_change_[b]);
      failures.push_back(
          {b, "no convergence in " + std::to_string(max_iterations_) + " iterations, last relative change " + change});
    }
    std::sort(failures.begin(), failures.end(), [](const auto& l, const auto& r) { return l.state < r.state; });
    return failures;
  }

 private:
  // slopes_ = f(z + Z_i) for every stage i of the listed states, in one batched evaluation.
  template <ModelWithThirdDerivatives M>
  void evaluate_slopes(const M& model, const PhaseSpaceBatch& x, const std::vector<std::size_t>& states) {
    const std::size_t n = x.dimension(), s = static_cast<std::size_t>(tableau_.stages), w = 2 * n;
    const std::size_t points = states.size() * s;
    q_.resize(points * n);
    p_.resize(points * n);
    dH_dq_.resize(points * n);
    dH_dp_.resize(points * n);
    for (std::size_t a = 0; a < states.size(); ++a)
      for (std::size_t i = 0; i < s; ++i) {
        const std::size_t b = states[a], point = a * s + i;
        const double* z = stages_.data() + (b * s + i) * w;
        for (std::size_t k = 0; k < n; ++k) {
          q_[point * n + k] = x.q(b)[k] + z[k];
          p_[point * n + k] = x.p(b)[k] + z[n + k];
        }
      }
    gradient_.evaluate(model, q_, p_, dH_dq_, dH_dp_, points);
    for (std::size_t a = 0; a < states.size(); ++a)
      for (std::size_t i = 0; i < s; ++i) {
        const std::size_t b = states[a], point = a * s + i;
        double* f = slopes_.data() + (b * s + i) * w;
        for (std::size_t k = 0; k < n; ++k) {
          f[k] = dH_dp_[point * n + k];
          f[n + k] = -dH_dq_[point * n + k];
        }
      }
  }

  // z' = z + dt sum_i b_i f(z + Z_i) for state b.
  void advance(PhaseSpaceBatch& x, std::size_t b, double dt) const {
    const std::size_t n = x.dimension(), s = static_cast<std::size_t>(tableau_.stages), w = 2 * n;
    for (std::size_t k = 0; k < w; ++k) {
      double sum = 0.0;
      for (std::size_t i = 0; i < s; ++i) sum += tableau_.b[i] * slopes_[(b * s + i) * w + k];
      (k < n ? x.q(b)[k] : x.p(b)[k - n]) += dt * sum;
    }
  }

  GaussLegendreTableau tableau_;
  HamiltonianGradient gradient_;
  int max_iterations_;
  std::vector<double> stages_, slopes_;        // Z and f(z + Z): state b, stage i, component k at (b*s + i)*2n + k
  std::vector<double> q_, p_, dH_dq_, dH_dp_;  // the stage points of the states still iterating
  std::vector<int> iterations_;
  std::vector<double> last_change_;          // per state: the relative change of its last iteration
  std::vector<std::size_t> active_, still_;  // the states iterating, and those that go on after this iteration
};

}  // namespace nonsep
