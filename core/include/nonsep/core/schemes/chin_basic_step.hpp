#pragma once
// Chin's basic algorithm, eq. (expalg) of S. A. Chin, "Explicit symplectic integrators for solving
// non-separable Hamiltonians":
//
//   T(eps) = exp(eps v2 V) exp(eps t2 T) exp(eps v1 V) exp(eps t1 T) exp(eps v0 V)
//            exp(eps t1 T) exp(eps v1 V) exp(eps t2 T) exp(eps v2 V)
//          = exp(eps^3 [T T V] + eps^5 E5 + ...)
//
// with t1 = -t2, v1 = 1/t2^2, v2 = -v1/2, v0 = -2 (v1 + v2), free t2 != 0 (default -6^(1/3), which makes
// e_TTTTV = e_VTTTV). Splitting the separable T(p) + V(q) this way advances the non-separable
// H_TTV = T_i V_ij T_j by dt = eps^3, so eps = cbrt(dt) (the real cube root, negative for dt < 0).
// The flows are   exp(c eps V): p <- p - c eps grad V(q)     exp(c eps T): q <- q + c eps grad T(p).
// Order 2/3: the global error is O(dt^(2/3)) (eq. torder).
//
// Form VVT interchanges T and V everywhere but keeps the coefficients (paper, after eq. torder): five drifts
// with v2, v1, v0, v1, v2 around four kicks with t2, t1, t1, t2. It solves H_VVT = V_i T_ij V_j.
//
// First-same-as-last: the outer flows' gradient depends only on the variable the inner flows change (grad V
// on q in TTV, grad T on p in VVT). The last outer gradient of a step is kept with a copy of the point it was
// evaluated at and reused by the next step when the state still holds that point bit for bit, whatever the
// new dt. A run of steps therefore costs 4 grad T + 4 grad V evaluations per step, plus one at the start. step_n()
// takes n steps in one call and compares and copies the point once for all of them instead of once per step. The one
// at the start is evaluated by the code that takes the steps: a model's kernel (below) when the steps go there, so
// that a run started again from a state (a checkpoint, a chunk) gives the numbers of steps that never stopped even
// where the kernel rounds differently from the evaluation path (a wider instruction set, fused multiply-adds).
//
// Stage observers: step() takes an optional observer, called after each of the nine flows as
//   observe(FlowStage{kick, coefficient}, eps, x)
// kick: true for p <- p - coefficient eps grad V(q), false for q <- q + coefficient eps grad T(p) (whichever
// form); eps as in the step (one entry, or one per state); x the states after the flow, which still hold the
// point the flow's gradient was evaluated at (q for a kick, p for a drift). This is how the tangent map
// (tangent_basic_step.hpp) follows the same nine stages without a second copy of the splitting; the default
// observer does nothing and leaves the stepping numbers as they are.
//
// The nine flows themselves are chin_stages (chin_stages.hpp), shared with the stepping kernels that plugins carry:
// for a model offering chin_steps (ModelWithChinSteps: a plugin with a kernel, as the host presents it), the steps
// no stage observer watches are handed to the model whole, coefficients, eps and the first-same-as-last gradient
// included, and come back with the same numbers and the same evaluation counts.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "nonsep/core/base/aligned_allocator.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/model.hpp"
#include "nonsep/core/base/phase_space_batch.hpp"
#include "nonsep/core/kernel/chin_stages.hpp"
#include "nonsep/core/schemes/integrator_description.hpp"

namespace nonsep {

struct NoStageObserver {
  void operator()(const FlowStage&, std::span<const double>, const PhaseSpaceBatch&) const {}
};

// The checks every step makes are inline and their failures out of line, so that a step of one state does not
// carry the frame that building the messages needs.
// eps = cbrt(dt) as the C library computes it at run time. Not inlined, so that the compiler cannot fold a step size
// it knows (a literal in a test or a program) into a cube root of its own, which may round differently from the
// library's: a step must give the same numbers whether dt comes from a job file or from the source.
[[gnu::noinline]] inline double runtime_cube_root(double dt) { return std::cbrt(dt); }

[[noreturn, gnu::cold, gnu::noinline]] inline void throw_bad_step_size(double dt) {
  throw InvalidArgument("step size dt must be finite and non-zero (found " + found_number(dt) + ")");
}
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_batch_does_not_fit(std::size_t model, std::size_t states) {
  throw InvalidArgument("the model has dimension " + std::to_string(model) + " but the states have dimension " +
                        std::to_string(states));
}

// Throws InvalidArgument unless dt is finite and non-zero.
inline void check_step_size(double dt) {
  if (!std::isfinite(dt) || dt == 0.0) [[unlikely]]
    throw_bad_step_size(dt);
}

template <class M>
void check_batch_fits(const M& model, const PhaseSpaceBatch& x) {
  const auto dimension = static_cast<std::size_t>(model.dimension());
  if (dimension != x.dimension()) [[unlikely]]
    throw_batch_does_not_fit(dimension, x.dimension());
}

class ChinBasicStep {
 public:
  explicit ChinBasicStep(HamiltonianForm form = HamiltonianForm::TTV, double t2 = ChinCoefficients::default_t2())
      : form_(form), c_(ChinCoefficients::from_t2(t2)) {}

  HamiltonianForm form() const { return form_; }
  const ChinCoefficients& coefficients() const { return c_; }
  const EvaluationCounts& evaluations() const { return evaluations_; }

  IntegratorDescription describe() const { return description(c_.t2); }
  // The description of the basic step of coefficient t2 (its scheme's, chin_schemes.hpp, without building one).
  static IntegratorDescription description(double t2) { return {"basic", Fraction(2, 3), true, true, 1, t2}; }

  // Advances every state of `x` by dt (finite, non-zero). Throws InvalidArgument on a bad dt or a batch whose
  // dimension differs from the model's; propagates the model's exceptions.
  template <Model M, class StageObserver = NoStageObserver>
  void step(const M& model, PhaseSpaceBatch& x, double dt, StageObserver&& observe = {}) {
    check_batch_fits(model, x);
    use_step_size(dt);
    advance(model, x, observe);
  }

  // Advances state b of `x` by dt[b] (one entry per state, each finite and non-zero): states of different step
  // sizes share each stage's model evaluation. State b gets bit for bit what step(model, x_b, dt[b]) gives it.
  // Throws InvalidArgument on a bad dt or dt.size() != x.count().
  template <Model M, class StageObserver = NoStageObserver>
  void step(const M& model, PhaseSpaceBatch& x, std::span<const double> dt, StageObserver&& observe = {}) {
    check_batch_fits(model, x);
    if (dt.size() != x.count())
      throw InvalidArgument("a batch of " + std::to_string(x.count()) + " states needs as many step sizes (found " +
                            std::to_string(dt.size()) + ")");
    eps_.resize(dt.size());
    substeps_ = 1;
    for (std::size_t b = 0; b < dt.size(); ++b) {  // runs of equal sizes (MPE's terms) share one cube root
      check_step_size(dt[b]);
      eps_[b] = b > 0 && dt[b] == dt[b - 1] ? eps_[b - 1] : cube_root(dt[b]);
    }
    advance(model, x, observe);
  }

  // Advances every state of `x` by `n` steps of dt (finite, non-zero): bit for bit what n calls of step(model, x, dt)
  // give, evaluations counted alike, but the per-step bookkeeping done once: the checks, cbrt(dt), and the
  // first-same-as-last comparison and copy of the point (x is this function's alone until it returns, so the
  // gradient of one step's last flow is the next step's first). Throws as step() does; after a model exception x
  // holds whatever the steps reached.
  template <Model M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    if (n == 0) return;
    check_batch_fits(model, x);
    use_step_size(dt);
    begin_steps(model, x);
    NoStageObserver none;
    stages(model, x, none, n);
    end_steps(x);
  }

  // Advances every state of `x` by `n` times the schedule `dts` of basic steps (each finite and non-zero): bit for
  // bit n times the calls step(model, x, dts[0]), step(model, x, dts[1]), ..., evaluations counted alike, with the
  // per-step bookkeeping done once, as step_n does; a model with a kernel takes the whole run in one call. This is
  // how a composition's steps (TripletComposition::step_n) reach the kernel whole. Throws as step_n does.
  template <Model M>
  void step_schedule_n(const M& model, PhaseSpaceBatch& x, std::span<const double> dts, std::uint64_t n) {
    if (n == 0 || dts.empty()) return;
    check_batch_fits(model, x);
    for (double dt : dts) check_step_size(dt);
    eps_.resize(dts.size());
    for (std::size_t s = 0; s < dts.size(); ++s) eps_[s] = cube_root(dts[s]);
    substeps_ = dts.size();
    begin_steps(model, x);
    NoStageObserver none;
    stages(model, x, none, n);
    end_steps(x);
  }

  // Advances every state of `x` by `n` steps of the multi-product expansion with `weights` (c_1..c_m, m >= 2) and
  // step size dt, in one call of the model's kernel when it has one (ModelWithChinSteps): bit for bit what n steps of
  // MultiProductExpansion<ChinBasicStep> give, evaluations counted alike (m (m + 1) / 2 basic steps a step, and one
  // outer gradient at each combined point the next step starts from). Returns false, having done nothing, when no
  // kernel is at hand (the caller takes the expansion's steps itself). Throws as step_n does; after a model
  // exception x holds whatever the steps reached.
  template <Model M>
  bool step_expansion_n(const M& model, PhaseSpaceBatch& x, double dt, std::span<const double> weights,
                        std::uint64_t n) {
    if constexpr (!ModelWithChinSteps<M>) {
      return false;
    } else {
      if (n == 0) return true;
      check_batch_fits(model, x);
      check_step_size(dt);
      const std::size_t m = weights.size();
      eps_.resize(m);
      for (std::size_t k = 1; k <= m; ++k) eps_[k - 1] = cube_root(dt / static_cast<double>(k));
      substeps_ = 1;
      begin_steps(model, x);
      const std::size_t count = x.count();
      const ChinStepsCall call{form_, c_, eps_, 1, n, count, x.q(), x.p(), outer_gradient_, inner_gradient_, weights};
      if (!model.chin_steps(call)) {
        cache_valid_ = true;  // untouched: still the gradient at x's point, as prime() left it
        return false;
      }
      const std::uint64_t basic_steps = n * m * (m + 1) / 2;
      evaluations_.grad_T += 4 * basic_steps * count;
      evaluations_.grad_V += 4 * basic_steps * count;
      (form_ == HamiltonianForm::TTV ? evaluations_.grad_V : evaluations_.grad_T) += (n - 1) * count;
      return true;  // the cache stays invalid: the outer gradient at the combined point is not at hand
    }
  }

  // Advances every state of `x` by `n` times the schedule `dts` of basic steps (each finite and non-zero) through
  // `kernel`, a callable kernel(const ChinStepsCall&) -> bool that takes the call's steps (with whatever it carries
  // along: a tangent kernel's vectors) or returns false, having done nothing, when none is at hand. The gradient the
  // steps start from comes from the same kernel (a call of no steps) unless cached, as prime() says. Returns whether
  // the kernel took the steps; then x holds bit for bit what step_schedule_n gives through a kernel of the same code,
  // evaluations counted alike. Throws as step_schedule_n does.
  template <Model M, class Kernel>
  bool step_schedule_by(const M& model, PhaseSpaceBatch& x, std::span<const double> dts, std::uint64_t n,
                        Kernel&& kernel) {
    if (n == 0 || dts.empty()) return true;
    check_batch_fits(model, x);
    for (double dt : dts) check_step_size(dt);
    eps_.resize(dts.size());
    for (std::size_t s = 0; s < dts.size(); ++s) eps_[s] = cube_root(dts[s]);
    substeps_ = dts.size();
    const std::size_t size = x.size(), count = x.count();
    if (inner_gradient_.size() != size) inner_gradient_.resize(size);
    prime_by(model, x, kernel);
    const ChinStepsCall call{form_, c_, eps_, substeps_, n, count, x.q(), x.p(), outer_gradient_, inner_gradient_, {}};
    cache_valid_ = false;
    if (!kernel(call)) {
      cache_valid_ = true;  // untouched: still the gradient at x's point
      return false;
    }
    evaluations_.grad_T += 4 * n * substeps_ * count;
    evaluations_.grad_V += 4 * n * substeps_ * count;
    end_steps(x);
    return true;
  }

  // Makes sure the outer gradient at x's current point is at hand (evaluates it unless cached). A model with a kernel
  // (ModelWithChinSteps) evaluates it there, in a call of no steps (chin_stages.hpp): the gradient the kernel's steps
  // start from is then the one its own steps would have left, bit for bit, so steps started again from a state
  // (after a checkpoint, a new chunk, a multi-product expansion's combined point) give the numbers of steps that
  // never stopped, on any instruction set. The evaluation path evaluates it through the model's gradient.
  template <Model M>
  void prime(const M& model, const PhaseSpaceBatch& x) {
    prime_for(model, x, true);
  }

  // The first-same-as-last gradient and the point it belongs to, for wrappers that restart from a saved state
  // (MultiProductExpansion).
  struct Cache {
    std::vector<double> at, gradient;
  };
  // Into `cache`, reusing its storage (a wrapper saving every step allocates nothing once warmed up).
  void save_cache(Cache& cache) const {
    if (cache_valid_)
      cache.at.assign(cached_at_.begin(), cached_at_.end());
    else
      cache.at.clear();
    cache.gradient.assign(outer_gradient_.begin(), outer_gradient_.end());
  }
  void restore_cache(const Cache& cache) {
    cached_at_.assign(cache.at.begin(), cache.at.end());
    outer_gradient_.assign(cache.gradient.begin(), cache.gradient.end());
    cache_valid_ = true;  // an empty `at` (saved while invalid) matches no batch
  }
  // Keeps the cache of the batch's first `size` numbers of q and of p (its first size / n states, layout b*n + i):
  // for a wrapper that drops the batch's last states (PhaseSpaceBatch::resize), without copying the rest.
  void keep_cache_prefix(std::size_t size) {
    if (cached_at_.size() > size) cached_at_.resize(size);
    if (outer_gradient_.size() > size) outer_gradient_.resize(size);
  }

 private:
  // One basic step of every state; eps_ holds eps = cbrt(dt), one for all states or one per state.
  template <Model M, class StageObserver>
  void advance(const M& model, PhaseSpaceBatch& x, StageObserver& observe) {
    begin_steps(model, x, std::is_same_v<std::decay_t<StageObserver>, NoStageObserver>);
    stages(model, x, observe, 1);
    end_steps(x);
  }

  // prime(); `through_kernel` false when the steps that follow go through the evaluation path (a stage observer
  // watches them), which then evaluates their first gradient too.
  template <Model M>
  void prime_for(const M& model, const PhaseSpaceBatch& x, bool through_kernel) {
    if constexpr (ModelWithChinSteps<M>)
      if (through_kernel) return prime_by(model, x, [&](const ChinStepsCall& call) { return model.chin_steps(call); });
    prime_by(model, x, [](const ChinStepsCall&) { return false; });
  }
  // The same with the gradient from `kernel` (kernel(call) -> bool, false: none at hand), else the evaluation path.
  template <Model M, class Kernel>
  void prime_by(const M& model, const PhaseSpaceBatch& x, Kernel&& kernel) {
    const bool ttv = form_ == HamiltonianForm::TTV;
    std::span<const double> inner = ttv ? x.q() : x.p();
    if (cache_valid_ && cached_at_.size() == inner.size() && same_bits(cached_at_, inner)) return;
    cache_valid_ = false;
    outer_gradient_.resize(inner.size());
    cached_at_.assign(inner.begin(), inner.end());
    if (!kernel_gradient(kernel, x.count())) evaluate(model, ttv, cached_at_, outer_gradient_, x.count());
    cache_valid_ = true;
  }

  // Before a run of steps: the outer gradient at x's point at hand, the work arrays sized. The gradient is
  // overwritten from the first inner flow on: should the model throw before the run's last evaluation, the cache
  // must not claim it belongs to any point.
  template <Model M>
  void begin_steps(const M& model, const PhaseSpaceBatch& x, bool through_kernel = true) {
    const std::size_t size = x.size();
    if (inner_gradient_.size() != size) inner_gradient_.resize(size);
    prime_for(model, x, through_kernel);
    cache_valid_ = false;
  }
  // After it: the outer gradient belongs to x's inner variable, for the next step's first flow.
  void end_steps(const PhaseSpaceBatch& x) {
    std::span<const double> inner = form_ == HamiltonianForm::TTV ? x.q() : x.p();
    if (cached_at_.size() != inner.size()) cached_at_.resize(inner.size());
    std::copy(inner.begin(), inner.end(), cached_at_.begin());
    cache_valid_ = true;
  }

  // `steps` times the substeps_ basic steps of eps_ (chin_stages.hpp: each the nine flows of eq. (expalg)), from
  // outer_gradient_ at x's current point;
  // leaves in outer_gradient_ the outer gradient at the new point. Steps that no observer watches go to the model's
  // kernel when it offers one (ModelWithChinSteps), the same numbers and evaluation counts.
  template <Model M, class StageObserver>
  void stages(const M& model, PhaseSpaceBatch& x, StageObserver& observe, std::uint64_t steps) {
    const std::size_t count = x.count();
    const ChinStepsCall call{form_,           c_, eps_, substeps_, steps, count, x.q(), x.p(), outer_gradient_,
                             inner_gradient_, {}};
    const std::uint64_t basic_steps = steps * substeps_;
    if constexpr (ModelWithChinSteps<M> && std::is_same_v<std::decay_t<StageObserver>, NoStageObserver>) {
      if (model.chin_steps(call)) {
        evaluations_.grad_T += 4 * basic_steps * count;
        evaluations_.grad_V += 4 * basic_steps * count;
        return;
      }
    }
    const CountedModel<M> counted{model, evaluations_};
    if (substeps_ != 1) {
      chin_scheduled_stages(counted, call);
      return;
    }
    chin_stages(counted, form_, c_, eps_, steps, count, x.q(), x.p(), outer_gradient_, inner_gradient_,
                [&](const FlowStage& stage) { observe(stage, std::span<const double>(eps_), std::as_const(x)); });
  }

  // The model with its gradient evaluations counted in `counts`, per state.
  template <Model M>
  struct CountedModel {
    const M& model;
    EvaluationCounts& counts;
    std::size_t dimension() const { return model.dimension(); }
    void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
      model.grad_T(p, out, count);
      counts.grad_T += count;
    }
    void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
      model.grad_V(q, out, count);
      counts.grad_V += count;
    }
  };

  // a and b (of equal size) hold the same numbers bit for bit; no early exit, so that the loop vectorizes.
  static bool same_bits(std::span<const double> a, std::span<const double> b) {
    std::uint64_t difference = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      difference |= std::bit_cast<std::uint64_t>(a[i]) ^ std::bit_cast<std::uint64_t>(b[i]);
    return difference == 0;
  }

  // One dt for every state: eps_ = {cbrt(dt)}. Throws InvalidArgument unless dt is finite and non-zero.
  void use_step_size(double dt) {
    check_step_size(dt);
    const double eps = cube_root(dt);
    if (eps_.size() != 1) eps_.resize(1);
    eps_[0] = eps;
    substeps_ = 1;
  }

  // cbrt(dt), remembered for the last few step sizes: a run steps with one dt (basic, MPE's terms) or cycles
  // through two or three (triplet compositions), and cbrt costs as much as a stage of paper1d.
  double cube_root(double dt) {
    for (const auto& [known, root] : roots_)
      if (known == dt) return root;
    roots_[next_root_] = {dt, runtime_cube_root(dt)};
    const double root = roots_[next_root_].second;
    next_root_ = (next_root_ + 1) % roots_.size();
    return root;
  }

  // The outer gradient at cached_at_ (count states) into outer_gradient_ by a kernel (kernel(call) -> bool), when one
  // is at hand: a call of no steps, whose other variable (p in TTV, q in VVT) is scratch it leaves alone. Returns false
  // without one.
  template <class Kernel>
  bool kernel_gradient(Kernel& kernel, std::size_t count) {
    const std::size_t size = cached_at_.size();
    if (inner_gradient_.size() != size) inner_gradient_.resize(size);
    if (other_variable_.size() != size) other_variable_.resize(size);
    static constexpr double unused_eps[1] = {1.0};  // a call of no steps takes none
    const bool ttv = form_ == HamiltonianForm::TTV;
    const std::span<double> at(cached_at_), other(other_variable_);
    const ChinStepsCall call{
        form_, c_, unused_eps, 1, 0, count, ttv ? at : other, ttv ? other : at, outer_gradient_, inner_gradient_, {}};
    if (!kernel(call)) return false;
    (ttv ? evaluations_.grad_V : evaluations_.grad_T) += count;
    return true;
  }

  template <Model M>
  void evaluate(const M& model, bool potential, std::span<const double> at, std::span<double> out, std::size_t count) {
    chin_gradient(CountedModel<M>{model, evaluations_}, potential, at, out, count);
  }

  HamiltonianForm form_;
  ChinCoefficients c_;
  EvaluationCounts evaluations_;
  AlignedDoubles outer_gradient_, inner_gradient_, cached_at_;  // streamed through by every stage
  AlignedDoubles other_variable_;  // kernel_gradient's scratch for the variable the outer gradient does not depend on
  bool cache_valid_ = false;       // outer_gradient_ is the outer gradient at cached_at_
  std::vector<double> eps_;        // cbrt(dt): one entry, one per state, or one per sub-step of a schedule
  std::size_t substeps_ = 1;       // basic steps per step: eps_.size() for a schedule (step_schedule_n), else 1
  std::array<std::pair<double, double>, 4> roots_{};  // (dt, cbrt(dt)); dt = 0 never asked (check_step_size)
  std::size_t next_root_ = 0;
};

}  // namespace nonsep
