#pragma once
// Gauss-Legendre collocation with s = 1 .. 8 stages (orders 2 .. 16), the implicit alternative to Chin's explicit
// schemes for any H: the implicit Runge-Kutta method applied to Hamilton's equations of the solved Hamiltonian itself,
//   z = (q, p),   dz/dt = f(z) = (dH/dp, -dH/dq)   (H_TTV or H_VVT, hamiltonian_gradient.hpp),
//   Z_i = dt sum_j a_ij f(z + Z_j),   z' = z + dt sum_i b_i f(z + Z_i),   i, j = 1..s.
// s = 1 is the implicit midpoint rule, z' = z + dt f((z + z')/2); there is no separate implicit_midpoint header.
// Symplectic and symmetric (time-reversible: the step of -dt undoes the step of dt) for any s, as collocation at
// the Gauss points (Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3 and VI.4); both hold up to
// the round-off the iteration below leaves.
//
// Round-off (Hairer, McLachlan, Razakarivony, BIT 48 (2008) 231; Antonana, Makazaga, Murua, Numer. Algorithms 76
// (2017) 861, the arrangement of IRKGL16): the step is computed as
//   L_i = hb_i f(z + Z_i),   Z_i = sum_j mu_ij L_j,   z' = z + sum_i L_i  (compensated),
// with hb_i = fl(dt b_i) and mu_ij = a_ij / b_j rounded so that mu_ij + mu_ji = 1 holds exactly in floating point
// (mu_ii = 1/2). Whatever the rounding of hb, the method with the coefficients b_i = hb_i / dt, a_ij = mu_ij b_j
// that the machine actually uses then satisfies b_i a_ij + b_j a_ji = b_i b_j exactly: it is symplectic. The sum
// z + sum_i L_i is compensated across steps (the rounding error of each step's addition, found by TwoSum, is added
// to the next step's increment): with a small step the increments change slowly, their rounding errors correlate
// from step to step, and uncompensated they add up like a drift.
//
// Solving the stages: fixed-point iteration L^{m+1}_i = hb_i f(z + Z^m_i), Z^{m+1}_i = sum_j mu_ij L^{m+1}_j, the
// whole batch
// together, f in one batched model call per iteration: while more than half of the states iterate, at the s stage
// points of every state of the batch (a state that has stopped is evaluated again at the points of its last
// iteration and the result is discarded: model time spent, but no gathering, no new point, and loops over the whole
// batch that vectorize); after that at the stage points of the states still iterating only, gathered. Stopping rule,
// per state, with delta_m = max_k |Z^{m+1}_k - Z^m_k| / max(|z|_inf, |Z^{m+1}|_inf) (the change relative to the state's
// size):
//   converged  when delta_m <= eps (one ulp of the state's largest component: nothing left to gain), or when
//              delta_m >= delta_{m-1} and delta_m <= 64 eps (the change stopped decreasing at round-off, GNI VIII.6);
//   failed     when an iterate is not finite, or after max_iterations iterations without converging.
// A converged state takes z' = z + sum_i L^{m+1}_i, from the evaluations of its last iteration, so a step
// costs s grad H per state per iteration and nothing more (counted so in evaluations(); the discarded evaluations
// above are not counted). A state that has converged stops iterating; the others
// go on. Each state's numbers therefore do not depend on the other states of the batch (batch equals single,
// bit for bit, as long as the model's per-state results do not). The iteration contracts when dt times the
// Lipschitz constant of f is small (about dt |Hess H| < 1); larger steps fail.
//
// Starting values (GNI VIII.6.1; IRKGL16): Z^0_i = sum_j nu_ij L_j with the L of the state's previous step, its
// collocation polynomial extrapolated to this step's stage points, when that step ended exactly where this one starts
// (bit for bit) with the same dt; else Z^0 = 0 (a trajectory's first step, the first after a failed one, a changed
// dt). Measured on paper1d (bench/comparators.cpp) this saves a fifth to a half of the iterations. What it needs, with
// the compensation above, is the stepper's private state per state (dt, the end point, the rounding errors and the L
// of the last step; stepper.hpp): the runner
// keeps it aligned with its states (compact, step_part) and checkpoints it (save_state, restore_state), so that a
// state's numbers still depend on its own history alone, and a resumed run continues bit for bit.
//
// A model with a kernel (ModelWithGaussSteps: a plugin's gauss_steps, as the host presents it) takes the step itself,
// blocks of states iterated to convergence with grad H inlined (kernel/gauss_stages.hpp, where the iteration, the
// starting values, the stopping rule and the compensated sum are written once for both): the same numbers, counts
// and private state. When a state of the batch fails there, the step is taken again through the evaluations below,
// which say what failed.
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
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/base/scheme_state.hpp"
#include "nonsep/core/kernel/gauss_stages.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/comparator_description.hpp"
#include "nonsep/core/schemes/gauss_failure.hpp"
#include "nonsep/core/schemes/gauss_legendre_tableau.hpp"

namespace nonsep {

// A state whose step failed: its index in the batch and why.
struct StateFailure {
  std::size_t state = 0;
  std::string reason;
};

class GaussLegendre {
 public:
  static constexpr int default_max_iterations = 100;

  // Order 2, 4, .., 16 (s = order/2 stages). Throws InvalidArgument on another order or max_iterations < 1.
  // `extrapolate` false starts every step from Z^0 = 0 (for measuring what the starting values save).
  explicit GaussLegendre(HamiltonianForm form = HamiltonianForm::TTV, int order = 2,
                         int max_iterations = default_max_iterations, bool extrapolate = true)
      : tableau_(GaussLegendreTableau::for_stages(order % 2 == 0 ? order / 2 : 0)),
        gradient_(form),
        max_iterations_(max_iterations),
        extrapolate_(extrapolate) {
    check(stages(), max_iterations);
  }
  // Throws InvalidArgument unless 1 <= stages <= GaussLegendreTableau::max_stages and max_iterations >= 1.
  static void check(int stages, int max_iterations) {
    GaussLegendreTableau::check_stages(stages);
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

  ComparatorDescription describe() const { return description(stages(), max_iterations_); }
  // The description of the method of this many stages and iterations (its schemes', comparator_schemes.hpp,
  // without building one).
  static ComparatorDescription description(int stages, int max_iterations) {
    ComparatorDescription d;
    d.scheme = "gauss";
    d.method = "Gauss-Legendre collocation, " + std::to_string(stages) + " stage" + (stages > 1 ? "s" : "") +
               (stages == 1 ? " (implicit midpoint rule)" : "");
    d.reference = "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VI.4, VIII.6";
    d.order = 2 * stages;
    d.properties = "symplectic and symmetric on (q, p), up to the round-off the fixed-point iteration leaves";
    d.grad_H_per_iteration = static_cast<std::uint64_t>(stages);
    d.cost = std::to_string(stages) +
             " grad H per state per fixed-point iteration; iterations run from the last step's stages "
             "extrapolated until the stages stop changing (at most " +
             std::to_string(max_iterations) + ")";
    d.parameters = {{"max_iterations", static_cast<double>(max_iterations)}};
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
                          ", dt = " + found_number(dt) + "): the fixed-point iteration failed";
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
    hb_.resize(s);
    for (std::size_t i = 0; i < s; ++i) hb_[i] = dt * tableau_.b[i];
    for (auto* v : {&final_q_, &final_p_}) v->resize(s * size);
    iterations_.assign(count, 0);
    fit_memory(count, n);
    if constexpr (ModelWithGaussSteps<M>) {
      if (step_by_kernel(model, x, dt)) return {};
      // No kernel at hand, or a state the kernel could not take: the whole step again, through the evaluations
      // (the same numbers), which say what failed and where.
      std::copy(start_q_.begin(), start_q_.end(), x.q().begin());
      std::copy(start_p_.begin(), start_p_.end(), x.p().begin());
      iterations_.assign(count, 0);
    }
    for (auto* v : {&stage_q_, &stage_p_}) v->assign(s * size, 0.0);
    start_from_last_step(x, dt);
    for (auto* v : {&next_q_, &next_p_, &L_q_, &L_p_, &dH_dq_, &dH_dp_}) v->resize(s * size);
    for (auto* v : {&change_, &scale_, &finite_probe_}) v->resize(size);
    keep_points_.assign(size, 0);
    last_change_.assign(count, std::numeric_limits<double>::infinity());
    active_.resize(count);
    for (std::size_t b = 0; b < count; ++b) active_[b] = b;
    std::vector<StateFailure> failures;
    for (int m = 0; m < max_iterations_ && !active_.empty(); ++m) {
      // While most states iterate, evaluate the whole batch (no gathering; the loops run over all of it); once
      // half of them have stopped, only those still iterating.
      if (2 * active_.size() > count) {
        evaluate_whole_batch(model, s, count);
        next_iterate(0, size, size);
      } else {
        evaluate_gathered(model, s, n, size);
        for (std::size_t b : active_) next_iterate(b * n, b * n + n, size);
      }
      evaluations_.grad_H += s * active_.size();
      still_.clear();
      for (std::size_t b : active_) {
        ++iterations_[b];
        const auto [relative, finite] =
            gauss_state_change(change_.data() + b * n, scale_.data() + b * n, finite_probe_.data() + b * n, n);
        const bool converged = gauss_converged(relative, last_change_[b]);
        if (finite && !converged) {
          last_change_[b] = relative;
          still_.push_back(b);
          continue;
        }
        std::fill_n(keep_points_.begin() + static_cast<std::ptrdiff_t>(b * n), n, ~std::uint64_t{0});
        if (finite) {
          keep_stage_points(b, n, s, size);
          advance(x, b, s, size);
          remember(x, b, dt);
        } else {
          failures.push_back(
              {b, gauss_not_finite_reason(start_q_.data() + b * n, start_p_.data() + b * n, stage_q_.data() + b * n,
                                          stage_p_.data() + b * n, dH_dq_.data() + b * n, dH_dp_.data() + b * n, n, s,
                                          size, iterations_[b])});
        }
      }
      active_.swap(still_);
      stage_q_.swap(next_q_);
      stage_p_.swap(next_p_);
    }
    for (const StateFailure& failure : failures) memory_[failure.state * memory_width(n)] = 0.0;
    for (std::size_t b : active_) {
      memory_[b * memory_width(n)] = 0.0;
      failures.push_back({b, gauss_no_convergence_reason(max_iterations_, last_change_[b])});
    }
    std::sort(failures.begin(), failures.end(), [](const auto& l, const auto& r) { return l.state < r.state; });
    return failures;
  }

  // Private state per state (stepper.hpp), so that a runner keeps the starting values aligned with its states.
  // Redoes one step for part of a batch: `part` holds states first .. first + part.count() - 1 of a batch of `total`
  // whose step `before` (this stepper as it was before the step) was to take; their last steps come from `before`
  // and what this step leaves is written back into this stepper's. Errors as step(); the other states' private
  // state is kept either way.
  template <HamiltonianModel M>
  void step_part(const M& model, PhaseSpaceBatch& part, const GaussLegendre& before, std::size_t first,
                 std::size_t total, double dt) {
    const std::size_t width = memory_width(part.dimension()), rows = part.count() * width;
    std::vector<double> all = memory_.size() == total * width ? memory_ : std::vector<double>(total * width, 0.0);
    if (before.memory_.size() == total * width)
      memory_.assign(before.memory_.begin() + static_cast<std::ptrdiff_t>(first * width),
                     before.memory_.begin() + static_cast<std::ptrdiff_t>(first * width + rows));
    else
      memory_.assign(rows, 0.0);
    try {
      step(model, part, dt);
    } catch (...) {
      std::fill_n(all.begin() + static_cast<std::ptrdiff_t>(first * width), rows, 0.0);
      memory_ = std::move(all);
      throw;
    }
    std::copy(memory_.begin(), memory_.end(), all.begin() + static_cast<std::ptrdiff_t>(first * width));
    memory_ = std::move(all);
  }
  // The states with retire[b] true leave the batch.
  void compact(const std::vector<bool>& retire) {
    if (retire.empty() || memory_.size() % retire.size() != 0) return;
    const std::size_t width = memory_.size() / retire.size();
    std::size_t kept = 0;
    for (std::size_t b = 0; b < retire.size(); ++b)
      if (!retire[b]) {
        std::copy_n(memory_.begin() + static_cast<std::ptrdiff_t>(b * width), width,
                    memory_.begin() + static_cast<std::ptrdiff_t>(kept * width));
        ++kept;
      }
    memory_.resize(kept * width);
  }
  // Column "gauss_last_step", 1 + 4n + 2sn numbers per state of `states`: dt (0: no last step), the end point q, p,
  // the rounding errors of its sum (q, p), and the L of the stages (q parts, then p parts, stage-major).
  SchemeState save_state(const PhaseSpaceBatch& states) const {
    const std::size_t width = memory_width(states.dimension()), size = states.count() * width;
    return {{{"gauss_last_step", width, memory_.size() == size ? memory_ : std::vector<double>(size, 0.0)}}, {}};
  }
  void restore_state(const SchemeState& state) {
    if (state.columns.size() == 1) memory_ = state.columns[0].values;
  }
  std::vector<SchemeFigure> report() const { return {}; }

 private:
  std::size_t memory_width(std::size_t n) const { return gauss_memory_width(n, static_cast<std::size_t>(stages())); }

  // Sizes the memory to a batch of `count` states of dimension n, forgetting it when the batch is not the one it
  // belongs to.
  void fit_memory(std::size_t count, std::size_t n) {
    if (memory_.size() != count * memory_width(n)) memory_.assign(count * memory_width(n), 0.0);
  }

  // The step through the model's kernel (gauss_stages.hpp, ModelWithGaussSteps): true when the kernel took it and
  // every state converged (then counted, its memory and stage points kept as the evaluations' path would), false
  // otherwise (x and the work arrays are then unspecified; the memory is as before).
  template <HamiltonianModel M>
  bool step_by_kernel(const M& model, PhaseSpaceBatch& x, double dt) {
    const std::size_t count = x.count(), s = static_cast<std::size_t>(tableau_.stages);
    outcomes_.assign(count, GaussOutcome::no_convergence);
    next_memory_.resize(memory_.size());
    const GaussStepsCall call{gradient_.form(),
                              s,
                              max_iterations_,
                              dt,
                              tableau_.mu,
                              hb_,
                              extrapolate_ ? std::span<const double>(tableau_.nu) : std::span<const double>(),
                              count,
                              x.q(),
                              x.p(),
                              memory_,
                              next_memory_,
                              final_q_,
                              final_p_,
                              iterations_,
                              outcomes_};
    if (!model.gauss_steps(call)) return false;
    for (const GaussOutcome outcome : outcomes_)
      if (outcome != GaussOutcome::converged) return false;
    for (std::size_t b = 0; b < count; ++b) evaluations_.grad_H += s * static_cast<std::uint64_t>(iterations_[b]);
    memory_.swap(next_memory_);
    return true;
  }

  // Z^0 (stage_q_, stage_p_, zero on entry) and the carried rounding errors from each state's last step where it
  // continues it (see above), zero elsewhere; the memory fits the batch (fit_memory).
  void start_from_last_step(const PhaseSpaceBatch& x, double dt) {
    const std::size_t count = x.count(), n = x.dimension(), s = static_cast<std::size_t>(stages()),
                      width = memory_width(n), size = count * n;
    compensation_q_.assign(size, 0.0);
    compensation_p_.assign(size, 0.0);
    for (std::size_t b = 0; b < count; ++b) {
      const double* row = memory_.data() + b * width;
      if (!gauss_continues(row, x.q(b).data(), x.p(b).data(), n, dt)) continue;
      std::copy_n(row + 1 + 2 * n, n, compensation_q_.begin() + static_cast<std::ptrdiff_t>(b * n));
      std::copy_n(row + 1 + 3 * n, n, compensation_p_.begin() + static_cast<std::ptrdiff_t>(b * n));
      if (extrapolate_)
        gauss_extrapolate(row, tableau_.nu.data(), s, n, stage_q_.data() + b * n, stage_p_.data() + b * n, size);
    }
  }

  // State b's step, for the next: dt, its end point, the rounding errors of its sum and its L.
  void remember(const PhaseSpaceBatch& x, std::size_t b, double dt) {
    const std::size_t n = x.dimension(), size = x.count() * n;
    gauss_remember(memory_.data() + b * memory_width(n), dt, x.q(b).data(), x.p(b).data(),
                   compensation_q_.data() + b * n, compensation_p_.data() + b * n, L_q_.data() + b * n,
                   L_p_.data() + b * n, size, static_cast<std::size_t>(stages()), n);
  }

  // The work arrays are stage-major, so that the loops over the batch run over contiguous memory: stage i, component
  // k of state b at i*size + b*n + k (size = count*n) in the stages Z^m (stage_q_, stage_p_), the next iterate
  // Z^{m+1} (next_q_, next_p_; the two swap after each iteration), L^{m+1} (L_q_, L_p_), the stage points z + Z^m
  // (q_, p_; gathered: in
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

  // points[e] = start[e] + stage[e] where keep[e] is 0; where it is all ones, points[e] stays (a state that stopped
  // iterating keeps the points of its last evaluation). A select on the bits, because GCC does not vectorize a
  // conditional on a floating-point sum under -ftrapping-math (the default).
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

  // Components [first, last) of the flat state index: L^{m+1}_i = hb_i f(z + Z^m_i) with f = (dH/dp, -dH/dq) into
  // L_q_, L_p_, Z^{m+1}_i = sum_j mu_ij L^{m+1}_j into next_q_, next_p_, and per component the largest change
  // |Z^{m+1} - Z^m| and size max(|z|, |Z^{m+1}|) over the stages, and a probe that is NaN when some Z^{m+1} is not
  // finite (0 * inf and 0 * NaN are NaN). The stage count is a template argument so that the sums unroll and the
  // loop over components vectorizes.
  void next_iterate(std::size_t first, std::size_t last, std::size_t size) {
    gauss_with_stages(static_cast<std::size_t>(tableau_.stages), [&]<std::size_t S>() {
      double mu[S * S], hb[S];
      std::copy_n(tableau_.mu.begin(), S * S, mu);
      std::copy_n(hb_.begin(), S, hb);
      gauss_next_iterate<S>(mu, hb, first, last, size, dH_dq_.data(), dH_dp_.data(), stage_q_.data(), stage_p_.data(),
                            start_q_.data(), start_p_.data(), L_q_.data(), L_p_.data(), next_q_.data(), next_p_.data(),
                            change_.data(), scale_.data(), finite_probe_.data());
    });
  }

  // The points z + Z^m_i of state b's last evaluation (the same sums as the evaluation's) into final_q_, final_p_.
  void keep_stage_points(std::size_t b, std::size_t n, std::size_t s, std::size_t size) {
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t e = b * n; e < b * n + n; ++e) {
        final_q_[i * size + e] = start_q_[e] + stage_q_[i * size + e];
        final_p_[i * size + e] = start_p_[e] + stage_p_[i * size + e];
      }
  }

  // z' = z + sum_i L_i for state b, with the L of its last iteration, compensated: the increment carries the last
  // step's rounding error, and this addition's own (TwoSum, exact) is kept for the next.
  void advance(PhaseSpaceBatch& x, std::size_t b, std::size_t s, std::size_t size) {
    const std::size_t n = x.dimension();
    for (std::size_t e = b * n; e < b * n + n; ++e) {
      double sum_q = 0.0, sum_p = 0.0;
      for (std::size_t i = 0; i < s; ++i) {
        sum_q += L_q_[i * size + e];
        sum_p += L_p_[i * size + e];
      }
      gauss_compensated_add(x.q()[e], sum_q, compensation_q_[e]);
      gauss_compensated_add(x.p()[e], sum_p, compensation_p_[e]);
    }
  }

  GaussLegendreTableau tableau_;
  HamiltonianGradient gradient_;
  int max_iterations_;
  bool extrapolate_;
  std::vector<double> memory_;       // per state: dt, end point, rounding errors and L of its last step (memory_width)
  std::vector<double> next_memory_;  // the kernel's memory of this step, kept once every state converged
  std::vector<double> compensation_q_, compensation_p_;  // per component: the rounding error the step carries
  EvaluationCounts evaluations_;           // grad_H of the states iterating (not of those evaluated again for nothing)
  std::vector<double> start_q_, start_p_;  // z, the states at the start of the step
  std::vector<double> hb_;                 // fl(dt b_i) of the current step
  std::vector<double> stage_q_, stage_p_, next_q_, next_p_, L_q_, L_p_, q_, p_, dH_dq_, dH_dp_, gathered_dH_dq_,
      gathered_dH_dp_;
  std::vector<double> change_, scale_, finite_probe_;
  std::vector<double> final_q_, final_p_;   // the stage points of each converged state's last evaluation
  std::vector<std::uint64_t> keep_points_;  // per component: 0 while its state iterates, then all ones
  std::vector<int> iterations_;
  std::vector<GaussOutcome> outcomes_;       // per state, from the kernel
  std::vector<double> last_change_;          // per state: the relative change of its last iteration
  std::vector<std::size_t> active_, still_;  // the states iterating, and those that go on after this iteration
};

}  // namespace nonsep
