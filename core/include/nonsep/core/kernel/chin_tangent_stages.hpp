#pragma once
// The tangent map of Chin's basic step, eq. (expalg), as a stepping kernel takes it: the nine flows of chin_stages
// (chin_stages.hpp) with, after each flow, its linear map applied to k tangent vectors per state, the model's
// Hessian-vector products inlined:
//   kick  p <- p - c eps grad V(q)   has   dp <- dp - c eps Hess V(q) dq
//   drift q <- q + c eps grad T(p)   has   dq <- dq + c eps Hess T(p) dp
// each at the point its flow started from (which the flow leaves unchanged). These are the operations of
// TangentBasicStep (tangent_basic_step.hpp) with a model that has Hessian-vector products, in the same order on every
// number, so a kernel compiled with the evaluation path's flags gives its states and vectors bit for bit
// (tests/core/test_chin_tangent_kernel.cpp). One product is not evaluated twice: the last outer flow of a step and the
// first of the next see the same point and the same vectors (no inner flow between them), so the next step reuses the
// product, which holds the same numbers.
//
// Tangent layout as in tangent_basic_step.hpp: vector j of state b at (b*k + j)*n, dq in tangent_q, dp in tangent_p.
#include <algorithm>
#include <concepts>
#include <cstddef>
#include <span>

#include "nonsep/core/base/hessian_products.hpp"
#include "nonsep/core/kernel/chin_stages.hpp"

namespace nonsep {

// What a tangent kernel is asked to do: the steps of `steps` (a ChinStepsCall without weights: basic steps or a
// schedule of them; with no steps, only the outer gradient at the point, as chin_stages.hpp says), with `vectors`
// (k >= 1) tangent vectors per state mapped along in tangent_q and tangent_p (count*k*n numbers each).
struct ChinTangentStepsCall {
  ChinStepsCall steps;
  std::size_t vectors;
  std::span<double> tangent_q, tangent_p;
};

// A model that may take whole runs of steps with their tangent maps itself (a plugin's tangent kernel):
//   m.chin_tangent_steps(call) -> bool   true when it advanced call's arrays as chin_tangent_stages would, false when
//   no
//                                        tangent kernel is at hand (the caller then steps through the evaluation path).
//                                        Throws ModelError when the model fails inside; the arrays are then
//                                        unspecified.
template <class M>
concept ModelWithChinTangentSteps = Model<M> && requires(const M& m, const ChinTangentStepsCall& call) {
  { m.chin_tangent_steps(call) } -> std::same_as<bool>;
};

// Scratch of chin_tangent_stages: the Hessian-vector products (count*k*n numbers) and, for k > 1, each point repeated
// k times (count*k*n). The caller owns it, so that a block in local arrays keeps it on the stack.
struct ChinTangentScratch {
  std::span<double> products, points;
};

// The steps of `call` with the tangent maps (requires ModelWithHessianProducts, chin_eps_fit without weights and
// the sizes above). StaticSize as for chin_stages (q's size, when known at compile time).
template <std::size_t StaticSize = 0, ModelWithHessianProducts M>
inline void chin_tangent_stages(const M& model, const ChinTangentStepsCall& call, ChinTangentScratch scratch) {
  const ChinStepsCall& c = call.steps;
  if (c.steps == 0) return;  // a call of no steps: the kernel's block evaluated its outer gradient
  const std::size_t count = c.count, k = call.vectors;
  const std::size_t n = StaticSize > 0 ? StaticSize / count : c.q.size() / count, size = count * k * n;
  bool product_current = false;  // scratch.products holds the last outer flow's products, still valid
  bool last_kick = false;
  std::span<const double> eps = c.eps;
  // The linear map of a flow, from the point it started at.
  const auto linear_map = [&](const FlowStage& stage) {
    const bool reuse = product_current && stage.kick == last_kick;
    last_kick = stage.kick;
    const std::span<const double> point = stage.kick ? c.q : c.p;
    const std::span<double> changed = stage.kick ? call.tangent_p : call.tangent_q;
    const std::span<const double> driver = stage.kick ? call.tangent_q : call.tangent_p;
    if (!reuse) {
      std::span<const double> points = point;
      if (k > 1) {
        for (std::size_t b = 0; b < count; ++b)
          for (std::size_t j = 0; j < k; ++j)
            std::copy_n(point.begin() + static_cast<std::ptrdiff_t>(b * n), n,
                        scratch.points.begin() + static_cast<std::ptrdiff_t>((b * k + j) * n));
        points = scratch.points.first(size);
      }
      if (stage.kick)
        model.hvp_V(points, driver.first(size), scratch.products.first(size), count * k);
      else
        model.hvp_T(points, driver.first(size), scratch.products.first(size), count * k);
    }
    // The outer flows' products stay valid until the next inner flow changes the point or the vectors they take.
    const bool outer = stage.kick == (c.form == HamiltonianForm::TTV);
    product_current = outer;
    const double sign = stage.kick ? -1.0 : 1.0;
    if (eps.size() == 1) {
      const double h = sign * stage.coefficient * eps[0];
      for (std::size_t i = 0; i < size; ++i) changed[i] += h * scratch.products[i];
      return;
    }
    for (std::size_t b = 0; b < count; ++b) {
      const double h = sign * stage.coefficient * eps[b];
      for (std::size_t i = b * k * n; i < (b + 1) * k * n; ++i) changed[i] += h * scratch.products[i];
    }
  };
  const auto basic_steps = [&](std::span<const double> step_eps, std::uint64_t steps) {
    eps = step_eps;
    chin_stages<StaticSize>(model, c.form, c.coefficients, step_eps, steps, count, c.q, c.p, c.outer_gradient,
                            c.inner_gradient, linear_map);
  };
  if (c.substeps == 1) {
    basic_steps(c.eps, c.steps);
    return;
  }
  for (std::uint64_t step = 0; step < c.steps; ++step)
    for (std::size_t s = 0; s < c.substeps; ++s) basic_steps(c.eps.subspan(s, 1), 1);  // products do not take eps
}

}  // namespace nonsep
