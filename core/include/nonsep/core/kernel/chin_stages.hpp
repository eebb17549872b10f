#pragma once
// The nine flows of Chin's basic algorithm, eq. (expalg), written once for every caller:
//
//   T(eps) = exp(eps v2 V) exp(eps t2 T) exp(eps v1 V) exp(eps t1 T) exp(eps v0 V)
//            exp(eps t1 T) exp(eps v1 V) exp(eps t2 T) exp(eps v2 V)
//
// (form TTV; form VVT interchanges T and V and keeps the coefficients: chin_basic_step.hpp explains both). Two
// callers instantiate it:
//   - ChinBasicStep, the evaluation path: the model's batched gradients, each a call across the plugin boundary
//     with the whole batch going through memory;
//   - the SDK's stepping kernel (plugins/sdk), inside each plugin: the same template with the plugin's model
//     inlined, over one state held in local arrays (a fixed small dimension: the compiler keeps q, p and the
//     gradients in registers through the nine flows) or a block of states that stays in the first-level cache.
// Both perform the same floating-point operations in the same order on every number, so for code compiled with
// the same flags (the baseline instruction set) the two paths agree bit for bit (tests/core, tests/host).
//
// chin_stages(model, form, c, eps, steps, count, q, p, outer_gradient, inner_gradient, after_flow) takes `steps`
// basic steps of `count` states (batch layout of model.hpp, dimension n = q.size() / count):
//   eps             cbrt(dt): one entry for every state, or one per state (count entries)
//   q, p            count*n each, advanced in place
//   outer_gradient  count*n: in, the outer gradient at the current point (grad V(q) in TTV, grad T(p) in VVT);
//                   out, the outer gradient at the final point (the first-same-as-last gradient of the next step)
//   inner_gradient  count*n scratch
//   after_flow      called after each flow as after_flow(FlowStage{kick, coefficient}); does nothing by default
// Each step evaluates 4 grad T and 4 grad V on the batch (model.grad_T(x, out, count), model.grad_V(...)). The
// arrays must not overlap. A model exception propagates, leaving the arrays at whatever the flows reached.
//
// chin_scheduled_stages(model, call) runs a ChinStepsCall (below): `steps` times a schedule of `substeps` basic
// steps, sub-step s with its own eps[s] (a triplet composition's composed step, triplet_composition.hpp), each
// sub-step chin_stages' own one step: the numbers of the basic steps taken one by one.
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/model.hpp"

namespace nonsep {

// The coefficients of eq. (expalg) as functions of the free parameter t2: t1 = -t2, v1 = 1/t2^2, v2 = -v1/2,
// v0 = -2 (v1 + v2).
struct ChinCoefficients {
  double t1, t2, v0, v1, v2;

  // -6^(1/3), correctly rounded, written out: std::cbrt is not correctly rounded in glibc (GCC folds the call at
  // compile time to this value, clang calls glibc at run time and gets 2 ulp less), and the default must be one
  // number on every compiler.
  static constexpr double default_t2() { return -1.8171205928321397; }
  // Throws InvalidArgument when t2 is zero or not finite.
  static ChinCoefficients from_t2(double t2) {
    if (!std::isfinite(t2) || t2 == 0.0)
      throw InvalidArgument(
          "t2 must be a finite non-zero number; the default is -6^(1/3) = -1.8171205928321397 (found " +
          found_number(t2) + ")");
    const double v1 = 1.0 / (t2 * t2);
    const double v2 = -v1 / 2.0;
    return ChinCoefficients{-t2, t2, -2.0 * (v1 + v2), v1, v2};
  }
};

// One flow of the splitting, as seen by an observer of the flows.
struct FlowStage {
  bool kick;           // p <- p - coefficient eps grad V(q); otherwise the drift q <- q + coefficient eps grad T(p)
  double coefficient;  // the splitting coefficient of this flow (v0, v1, v2, t1 or t2)
};

struct NoFlowObserver {
  void operator()(const FlowStage&) const {}
};

// The gradients a flow of the form needs: potential = true for grad V (of q), false for grad T (of p).
template <Model M>
inline void chin_gradient(const M& model, bool potential, std::span<const double> at, std::span<double> out,
                          std::size_t count) {
  if (potential)
    model.grad_V(at, out, count);
  else
    model.grad_T(at, out, count);
}

// What a stepping kernel is asked to do: `steps` times a schedule of `substeps` basic steps of `count` states, or
// `steps` steps of a multi-product expansion of those states.
//   eps       cbrt(dt) of each sub-step, for every state (substeps entries); or, with one sub-step, one entry for
//             every state or one per state (count entries); with weights, cbrt(dt / k) of term k = 1..m (m entries)
//   weights   empty: basic steps; m >= 2 entries: each step is the m-term expansion of MultiProductExpansion
//             (multi_product_expansion.hpp), weights[k-1] = c_k, substeps 1 (chin_expansion_stages.hpp). After the
//             call's last step the outer gradient is not that of the combined point: the caller evaluates it anew.
//   steps     0: no step; the call only evaluates outer_gradient at the point (q in TTV, p in VVT), leaving q and p
//             as they are (chin_outer_gradient below). This is how ChinBasicStep asks a kernel for the gradient its
//             steps start from, so that every gradient a kernel's steps use is evaluated by the kernel's own code:
//             a run restarted from its states (a checkpoint, a chunk started again) then gives the numbers of the
//             run it continues, whichever instruction set the kernel was compiled for.
//   the rest  chin_stages' arguments
struct ChinStepsCall {
  HamiltonianForm form;
  ChinCoefficients coefficients;
  std::span<const double> eps;
  std::size_t substeps;
  std::uint64_t steps;
  std::size_t count;
  std::span<double> q, p, outer_gradient, inner_gradient;
  std::span<const double> weights;
};

// Whether eps of `eps_size` entries fits a call of `substeps` sub-steps of `count` states with `terms` weights
// (ChinStepsCall above).
constexpr bool chin_eps_fit(std::size_t eps_size, std::size_t substeps, std::size_t count, std::size_t terms = 0) {
  if (terms != 0) return terms >= 2 && substeps == 1 && eps_size == terms && count > 0;
  return substeps >= 1 && (eps_size == substeps || (substeps == 1 && eps_size == count && count > 0));
}

// A model that may take whole runs of basic steps itself, with its gradients inlined (a plugin's kernel):
//   m.chin_steps(call) -> bool   true when it advanced call's arrays as chin_stages would (the same numbers for
//                                code built alike), false when no kernel is at hand for this call (none, another
//                                kernel version, or turned off): the caller then runs chin_scheduled_stages.
//                                Throws ModelError when the model fails inside; the arrays are then unspecified.
// ChinBasicStep uses it for the steps no flow observer watches, and for whole expansions (step_expansion_n). The
// evaluations it performs are counted as chin_stages' (4 grad T and 4 grad V per state and basic step; an expansion
// adds the outer gradient between its steps).
template <class M>
concept ModelWithChinSteps = Model<M> && requires(const M& m, const ChinStepsCall& call) {
  { m.chin_steps(call) } -> std::same_as<bool>;
};

// A call of no steps (ChinStepsCall::steps 0): the outer gradient at the call's point into call.outer_gradient; returns
// whether it was one (the callers below then do nothing else).
template <Model M>
inline bool chin_outer_gradient(const M& model, const ChinStepsCall& call) {
  if (call.steps != 0) return false;
  const bool ttv = call.form == HamiltonianForm::TTV;
  chin_gradient(model, ttv, ttv ? call.q : call.p, call.outer_gradient, call.count);
  return true;
}

// StaticSize, when not 0, is q's size known at compile time (a kernel's block in local arrays): the flows' loops then
// have a constant trip count, unroll, and keep a small state in registers.
template <std::size_t StaticSize = 0, Model M, class AfterFlow = NoFlowObserver>
inline void chin_stages(const M& model, HamiltonianForm form, const ChinCoefficients& c, std::span<const double> eps,
                        std::uint64_t steps, std::size_t count, std::span<double> q, std::span<double> p,
                        std::span<double> outer_gradient, std::span<double> inner_gradient,
                        AfterFlow&& after_flow = {}) {
  const bool ttv = form == HamiltonianForm::TTV;
  const std::span<double> outer = ttv ? p : q;
  const std::span<double> inner = ttv ? q : p;
  const double outer_sign = ttv ? -1.0 : 1.0;  // TTV: outer flows are kicks (p -= ...), VVT: drifts (q += ...)
  const double inner_sign = -outer_sign;
  const std::size_t n = count == 0 ? 0 : q.size() / count;
  // y += sign * coefficient * eps * gradient, state by state when the states have their own eps. One number (one
  // state of dimension 1) takes a scalar statement: the vectorized loop's alias check and prologue cost more than
  // its arithmetic.
  auto flow = [&](std::span<double> y, std::span<const double> gradient, double sign, double coefficient) {
    if (eps.size() == 1) {
      const double h = sign * coefficient * eps[0];
      if constexpr (StaticSize > 0) {
        for (std::size_t i = 0; i < StaticSize; ++i) y[i] += h * gradient[i];
        return;
      }
      if (y.size() == 1) {
        y[0] += h * gradient[0];
        return;
      }
      for (std::size_t i = 0; i < y.size(); ++i) y[i] += h * gradient[i];
      return;
    }
    for (std::size_t b = 0; b < count; ++b) {
      const double h = sign * coefficient * eps[b];
      for (std::size_t i = b * n; i < (b + 1) * n; ++i) y[i] += h * gradient[i];
    }
  };
  auto outer_flow = [&](double coefficient) {
    flow(outer, outer_gradient, outer_sign, coefficient);
    after_flow(FlowStage{ttv, coefficient});
  };
  auto inner_flow = [&](double coefficient) {
    chin_gradient(model, !ttv, outer, inner_gradient, count);  // TTV: grad T(p); VVT: grad V(q)
    flow(inner, inner_gradient, inner_sign, coefficient);
    after_flow(FlowStage{!ttv, coefficient});
    chin_gradient(model, ttv, inner, outer_gradient, count);  // TTV: grad V(q); VVT: grad T(p)
  };
  for (std::uint64_t step = 0; step < steps; ++step) {
    outer_flow(c.v2);
    inner_flow(c.t2);
    outer_flow(c.v1);
    inner_flow(c.t1);
    outer_flow(c.v0);
    inner_flow(c.t1);
    outer_flow(c.v1);
    inner_flow(c.t2);
    outer_flow(c.v2);
  }
}

// The steps of `call` (requires chin_eps_fit(call.eps.size(), call.substeps, call.count) and chin_stages' sizes; a
// call of no steps does nothing). StaticSize as for chin_stages. The kernels' blocks (chin_kernel.hpp) call this one
// and answer a call of no steps themselves, outside the arrays of their steps.
template <std::size_t StaticSize = 0, Model M>
inline void chin_scheduled_steps(const M& model, const ChinStepsCall& call) {
  if (call.substeps == 1) {
    chin_stages<StaticSize>(model, call.form, call.coefficients, call.eps, call.steps, call.count, call.q, call.p,
                            call.outer_gradient, call.inner_gradient);
    return;
  }
  for (std::uint64_t step = 0; step < call.steps; ++step)
    for (std::size_t s = 0; s < call.substeps; ++s)
      chin_stages<StaticSize>(model, call.form, call.coefficients, call.eps.subspan(s, 1), 1, call.count, call.q,
                              call.p, call.outer_gradient, call.inner_gradient);
}

// chin_scheduled_steps, or with no steps the outer gradient alone (chin_outer_gradient).
template <std::size_t StaticSize = 0, Model M>
inline void chin_scheduled_stages(const M& model, const ChinStepsCall& call) {
  if (chin_outer_gradient(model, call)) return;
  chin_scheduled_steps<StaticSize>(model, call);
}

}  // namespace nonsep
