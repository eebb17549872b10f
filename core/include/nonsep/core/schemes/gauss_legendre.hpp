#pragma once
// Gauss-Legendre collocation with s = 1, 2, 3 stages (orders 2, 4, 6), the implicit alternative to Chin's explicit
// schemes for any H: the implicit Runge-Kutta method applied to Hamilton's equations of the solved Hamiltonian itself,
//   z = (q, p),   dz/dt = f(z) = (dH/dp, -dH/dq)   (H_TTV or H_VVT, hamiltonian_gradient.hpp),
//   Z_i = dt sum_j a_ij f(z + Z_j),   z' = z + dt sum_i b_i f(z + Z_i),   i, j = 1..s.
// s = 1 is the implicit midpoint rule, z' = z + dt f((z + z')/2); there is no separate implicit_midpoint header.
// Symplectic and symmetric (time-reversible: the step of -dt undoes the step of dt) for any s, as collocation at
// the Gauss points (Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3 and VI.4); both hold up to
// the round-off the iteration below leaves.
//
// Solving the stages: fixed-point iteration Z^{m+1}_i = dt sum_j a_ij f(z + Z^m_j) from Z^0 = 0, the whole batch
// together, f in one batched model call per iteration: while more than half of the states iterate, at the s stage
// points of every state of the batch (a state that has stopped is evaluated again at the points of its last
// iteration and the result is discarded: model time spent, but no gathering, no new point, and loops over the whole
// batch that vectorize); after that at the stage points of the states still iterating only, gathered. Stopping rule,
// per state, with delta_m = max_k |Z^{m+1}_k - Z^m_k| / max(|z|_inf, |Z^{m+1}|_inf) (the change relative to the state's
// size):
//   converged  when delta_m <= eps (one ulp of the state's largest component: nothing left to gain), or when
//              delta_m >= delta_{m-1} and delta_m <= 64 eps (the change stopped decreasing at round-off, GNI VIII.6);
//   failed     when an iterate is not finite, or after max_iterations iterations without converging.
// A converged state takes z' = z + dt sum_i b_i f(z + Z^m_i) with the evaluations of its last iteration, so a step
// costs s grad H per state per iteration and nothing more (counted so in evaluations(); the discarded evaluations
// above are not counted). A state that has converged stops iterating; the others
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
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/comparator_description.hpp"

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
  const EvaluationCounts& evaluations() const { return evaluations_; }
  void add_evaluations(const EvaluationCounts& counts) { evaluations_ += counts; }
  // Iterations each state of the last step took (failed states: the iterations tried).
  std::span<const int> iterations() const { return iterations_; }
  // The stage points z + Z_i of the last step at which f was evaluated for the step's result, stage-major: stage i,
  // component k of state b at i*count*n + b*n + k (q and p apart); those of failed states are unspecified. The
  // tangent map (tangent_gauss_legendre.hpp) linearises there.
  std::span<const double> stage_points_q() const { return final_q_; }
  std::span<const double> stage_points_p() const { return final_p_; }

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
  template <HamiltonianModel M>
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
    throw ModelError(message);
  }

  // As step(), but returns the failed states instead of throwing ModelError; they keep their starting point.
  template <HamiltonianModel M>
  std::vector<StateFailure> try_step(const M& model, PhaseSpaceBatch& x, double dt) {
    check_step_size(dt);
    check_batch_fits(model, x);
    const std::size_t count = x.count(), n = x.dimension(), s = static_cast<std::size_t>(tableau_.stages);
    const std::size_t size = count * n;
    start_q_.assign(x.q().begin(), x.q().end());
    start_p_.assign(x.p().begin(), x.p().end());
    for (auto* v : {&stage_q_, &stage_p_}) v->assign(s * size, 0.0);
    for (auto* v : {&next_q_, &next_p_, &dH_dq_, &dH_dp_}) v->resize(s * size);
    for (auto* v : {&change_, &scale_, &finite_probe_}) v->resize(size);
    for (auto* v : {&final_q_, &final_p_}) v->resize(s * size);
    keep_points_.assign(size, 0);
    iterations_.assign(count, 0);
    last_change_.assign(count, std::numeric_limits<double>::infinity());
    active_.resize(count);
    for (std::size_t b = 0; b < count; ++b) active_[b] = b;
    std::vector<StateFailure> failures;
    const double eps = std::numeric_limits<double>::epsilon();
    for (int m = 0; m < max_iterations_ && !active_.empty(); ++m) {
      // While most states iterate, evaluate the whole batch (no gathering; the loops run over all of it); once
      // half of them have stopped, only those still iterating.
      if (2 * active_.size() > count) {
        evaluate_whole_batch(model, s, count);
        next_iterate(0, size, size, dt);
      } else {
        evaluate_gathered(model, s, n, size);
        for (std::size_t b : active_) next_iterate(b * n, b * n + n, size, dt);
      }
      evaluations_.grad_H += s * active_.size();
      still_.clear();
      for (std::size_t b : active_) {
        ++iterations_[b];
        double change = 0.0, scale = 0.0, probe = 0.0;
        for (std::size_t e = b * n; e < b * n + n; ++e) {
          change = std::max(change, change_[e]);
          scale = std::max(scale, scale_[e]);
          probe += finite_probe_[e];
        }
        const double relative = scale > 0.0 ? change / scale : 0.0;
        const bool finite = probe == 0.0;  // else NaN: an iterate is not finite
        const bool converged = relative <= eps || (relative >= last_change_[b] && relative <= 64 * eps);
        if (finite && !converged) {
          last_change_[b] = relative;
          still_.push_back(b);
          continue;
        }
        std::fill_n(keep_points_.begin() + static_cast<std::ptrdiff_t>(b * n), n, ~std::uint64_t{0});
        if (finite) {
          keep_stage_points(b, n, s, size);
          advance(x, b, s, size, dt);
        } else
          failures.push_back({b, not_finite_reason(b, n, s, size)});
      }
      active_.swap(still_);
      stage_q_.swap(next_q_);
      stage_p_.swap(next_p_);
    }
    for (std::size_t b : active_) {
      char change[32];
      std::snprintf(change, sizeof change, "%.3g", last_change_[b]);
      failures.push_back({b, "no convergence in " + std::to_string(max_iterations_) +
                                 " iterations, last relative change " + change +
                                 ": a smaller dt makes the iteration contract, unless the orbit runs off where grad H "
                                 "grows without bound (a non-compact energy shell)"});
    }
    std::sort(failures.begin(), failures.end(), [](const auto& l, const auto& r) { return l.state < r.state; });
    return failures;
  }

 private:
  // Why state b's iterate is not finite: the first stage point of its last iteration where grad H is not finite
  // (named, with the stage), or else the iterate itself overflowing.
  std::string not_finite_reason(std::size_t b, std::size_t n, std::size_t s, std::size_t size) const {
    const auto vector_text = [&](const std::vector<double>& start, const std::vector<double>& stage, std::size_t i) {
      std::string text = "(";
      char number[32];
      for (std::size_t e = b * n; e < b * n + n; ++e) {
        std::snprintf(number, sizeof number, "%.17g", start[e] + stage[i * size + e]);
        text += (e == b * n ? "" : ", ") + std::string(number);
      }
      return text + ")";
    };
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t e = b * n; e < b * n + n; ++e)
        if (!std::isfinite(dH_dq_[i * size + e]) || !std::isfinite(dH_dp_[i * size + e]))
          return "grad H is not finite at stage " + std::to_string(i + 1) + " of iteration " +
                 std::to_string(iterations_[b]) + ", q = " + vector_text(start_q_, stage_q_, i) +
                 ", p = " + vector_text(start_p_, stage_p_, i) +
                 ": H is not defined or not differentiable there, or the orbit ran off to where it overflows";
    return "an iterate is not finite after " + std::to_string(iterations_[b]) +
           " iterations: the stages overflowed; a smaller dt makes the iteration contract";
  }

  // The work arrays are stage-major, so that the loops over the batch run over contiguous memory: stage i, component
  // k of state b at i*size + b*n + k (size = count*n) in the stages Z^m (stage_q_, stage_p_), the next iterate
  // Z^{m+1} (next_q_, next_p_; the two swap after each iteration), the stage points z + Z^m (q_, p_; gathered: in
  // the order of active_) and dH/dq, dH/dp there. change_, scale_ and finite_probe_ hold per component (b*n + k)
  // what the last iteration found. The values of states that have stopped are left stale and never read. A state's
  // numbers never mix with another's, and its sums run in the same order whichever states are evaluated with it.

  // dH/dq, dH/dp at z + Z_i for every stage of every state, in one batched evaluation. A state that stopped iterating
  // is evaluated again at the stage points of its last iteration (its stages no longer change): model time spent for
  // nothing, but no gathering, and no point the model has not seen before.
  template <HamiltonianModel M>
  void evaluate_whole_batch(const M& model, std::size_t s, std::size_t count) {
    const std::size_t size = start_q_.size();
    q_.resize(s * size);
    p_.resize(s * size);
    for (std::size_t i = 0; i < s; ++i) {
      stage_points(start_q_.data(), stage_q_.data() + i * size, keep_points_.data(), q_.data() + i * size, size);
      stage_points(start_p_.data(), stage_p_.data() + i * size, keep_points_.data(), p_.data() + i * size, size);
    }
    gradient_.evaluate(model, q_, p_, dH_dq_, dH_dp_, s * count);
  }

  // points[e] = start[e] + stage[e] where keep[e] is 0; where it is all ones, points[e] stays. A select on the bits,
  // because GCC does not vectorize a conditional on a floating-point sum under -ftrapping-math (the default).
  static void stage_points(const double* __restrict start, const double* __restrict stage,
                           const std::uint64_t* __restrict keep, double* __restrict points, std::size_t size) {
    for (std::size_t e = 0; e < size; ++e) {
      const auto fresh = std::bit_cast<std::uint64_t>(start[e] + stage[e]);
      const auto kept = std::bit_cast<std::uint64_t>(points[e]);
      points[e] = std::bit_cast<double>((fresh & ~keep[e]) | (kept & keep[e]));
    }
  }

  // The same for the states still iterating only: their stage points gathered, evaluated, the gradients scattered
  // back to their places.
  template <HamiltonianModel M>
  void evaluate_gathered(const M& model, std::size_t s, std::size_t n, std::size_t size) {
    const std::size_t points = s * active_.size();
    q_.resize(points * n);
    p_.resize(points * n);
    gathered_dH_dq_.resize(points * n);
    gathered_dH_dp_.resize(points * n);
    for (std::size_t i = 0, g = 0; i < s; ++i)
      for (std::size_t b : active_)
        for (std::size_t e = b * n; e < b * n + n; ++e, ++g) {
          q_[g] = start_q_[e] + stage_q_[i * size + e];
          p_[g] = start_p_[e] + stage_p_[i * size + e];
        }
    gradient_.evaluate(model, q_, p_, gathered_dH_dq_, gathered_dH_dp_, points);
    for (std::size_t i = 0, g = 0; i < s; ++i)
      for (std::size_t b : active_)
        for (std::size_t e = b * n; e < b * n + n; ++e, ++g) {
          dH_dq_[i * size + e] = gathered_dH_dq_[g];
          dH_dp_[i * size + e] = gathered_dH_dp_[g];
        }
  }

  // Components [first, last) of the flat state index: Z^{m+1}_i = dt sum_j a_ij f(z + Z_j) with f = (dH/dp, -dH/dq)
  // into next_q_, next_p_, and per component the largest change |Z^{m+1} - Z^m| and size max(|z|, |Z^{m+1}|) over
  // the stages, and a probe that is NaN when some Z^{m+1} is not finite (0 * inf and 0 * NaN are NaN). The stage
  // count is a template argument so that the sums unroll and the loop over components vectorizes.
  void next_iterate(std::size_t first, std::size_t last, std::size_t size, double dt) {
    switch (tableau_.stages) {
      case 1:
        return next_iterate<1>(first, last, size, dt);
      case 2:
        return next_iterate<2>(first, last, size, dt);
      default:
        return next_iterate<3>(first, last, size, dt);
    }
  }
  template <std::size_t S>
  void next_iterate(std::size_t first, std::size_t last, std::size_t size, double dt) {
    double a[S * S];
    std::copy_n(tableau_.a.begin(), S * S, a);
    next_iterate_kernel<S>(a, dt, first, last, size, dH_dq_.data(), dH_dp_.data(), stage_q_.data(), stage_p_.data(),
                           start_q_.data(), start_p_.data(), next_q_.data(), next_p_.data(), change_.data(),
                           scale_.data(), finite_probe_.data());
  }
  // The arrays do not overlap (__restrict: without it GCC gives up on the many checks for overlap it would need).
  template <std::size_t S>
  static void next_iterate_kernel(const double* a, double dt, std::size_t first, std::size_t last, std::size_t size,
                                  const double* __restrict dH_dq, const double* __restrict dH_dp,
                                  const double* __restrict z_q, const double* __restrict z_p,
                                  const double* __restrict start_q, const double* __restrict start_p,
                                  double* __restrict next_q, double* __restrict next_p, double* __restrict change,
                                  double* __restrict scale, double* __restrict probe) {
    for (std::size_t e = first; e < last; ++e) {
      double largest_change = 0.0, largest = larger(std::abs(start_q[e]), std::abs(start_p[e])), nan = 0.0;
      for (std::size_t i = 0; i < S; ++i) {
        double sum_q = 0.0, sum_p = 0.0;
        for (std::size_t j = 0; j < S; ++j) {
          sum_q += a[i * S + j] * dH_dp[j * size + e];
          sum_p += a[i * S + j] * -dH_dq[j * size + e];
        }
        sum_q *= dt;
        sum_p *= dt;
        next_q[i * size + e] = sum_q;
        next_p[i * size + e] = sum_p;
        largest_change =
            larger(largest_change, larger(std::abs(sum_q - z_q[i * size + e]), std::abs(sum_p - z_p[i * size + e])));
        largest = larger(largest, larger(std::abs(sum_q), std::abs(sum_p)));
        nan += 0.0 * sum_q + 0.0 * sum_p;
      }
      change[e] = largest_change;
      scale[e] = largest;
      probe[e] = nan;
    }
  }

  // std::max by value: the same result (a < b ? b : a), but no reference to a temporary, which keeps GCC from
  // vectorizing the loop.
  static double larger(double a, double b) { return a < b ? b : a; }

  // The points z + Z^m_i of state b's last evaluation (the same sums as the evaluation's) into final_q_, final_p_.
  void keep_stage_points(std::size_t b, std::size_t n, std::size_t s, std::size_t size) {
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t e = b * n; e < b * n + n; ++e) {
        final_q_[i * size + e] = start_q_[e] + stage_q_[i * size + e];
        final_p_[i * size + e] = start_p_[e] + stage_p_[i * size + e];
      }
  }

  // z' = z + dt sum_i b_i f(z + Z_i) for state b, with the gradients of its last iteration.
  void advance(PhaseSpaceBatch& x, std::size_t b, std::size_t s, std::size_t size, double dt) const {
    const std::size_t n = x.dimension();
    for (std::size_t e = b * n; e < b * n + n; ++e) {
      double sum_q = 0.0, sum_p = 0.0;
      for (std::size_t i = 0; i < s; ++i) {
        sum_q += tableau_.b[i] * dH_dp_[i * size + e];
        sum_p += tableau_.b[i] * -dH_dq_[i * size + e];
      }
      x.q()[e] += dt * sum_q;
      x.p()[e] += dt * sum_p;
    }
  }

  GaussLegendreTableau tableau_;
  HamiltonianGradient gradient_;
  int max_iterations_;
  EvaluationCounts evaluations_;           // grad_H of the states iterating (not of those evaluated again for nothing)
  std::vector<double> start_q_, start_p_;  // z, the states at the start of the step
  std::vector<double> stage_q_, stage_p_, next_q_, next_p_, q_, p_, dH_dq_, dH_dp_, gathered_dH_dq_, gathered_dH_dp_;
  std::vector<double> change_, scale_, finite_probe_;
  std::vector<double> final_q_, final_p_;   // the stage points of each converged state's last evaluation
  std::vector<std::uint64_t> keep_points_;  // per component: 0 while its state iterates, then all ones
  std::vector<int> iterations_;
  std::vector<double> last_change_;          // per state: the relative change of its last iteration
  std::vector<std::size_t> active_, still_;  // the states iterating, and those that go on after this iteration
};

}  // namespace nonsep
