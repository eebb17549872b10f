#pragma once
// The tangent map of Chin's basic step, eq. (expalg): the exact derivative of the numerical one-step map,
// applied to k tangent vectors per state alongside the step itself.
//
// Each flow of the splitting is a shear whose derivative is again a shear:
//   kick  p <- p - c eps grad V(q)   has   dp <- dp - c eps Hess V(q) dq
//   drift q <- q + c eps grad T(p)   has   dq <- dq + c eps Hess T(p) dp
// The derivative of the nine-flow product is the product of these nine linear maps, each at the point its flow
// started from (q for a kick, p for a drift, which the flow leaves unchanged). TangentBasicStep does not repeat
// the splitting: it steps the states with a ChinBasicStep and applies the linear maps from that step's stage
// observer (chin_basic_step.hpp), so the states get bit for bit the numbers of ChinBasicStep::step, in either
// form (VVT: kicks with the t coefficients, drifts with the v, as the basic step orders them), for either sign
// of dt. Each linear map has determinant 1 and preserves the symplectic form dq.dp' - dp.dq', so the tangent
// map M of a step satisfies M^T J M = J to round-off.
//
// Tangent layout: a PhaseSpaceBatch of count * k entries of the states' dimension n; tangent vector j
// (0 <= j < k) of state b is entry b*k + j, its dq in q() and its dp in p() (component i at (b*k + j)*n + i).
// k is tangents.count() / x.count(), between 1 and 2n.
//
// Cost: besides the step's gradients, 4 Hess T + 4 Hess V evaluations per step (batched over the states, one
// model call per stage), plus one at the start: the Hessian of the outer flows is cached with the point it
// belongs to and reused while the state still holds that point bit for bit, as the basic step does with its
// gradient. Counted per state in hessian_evaluations(). Scratch storage grows to the largest batch seen and is
// reused: steady stepping does not allocate. A model with Hessian-vector products (hessian_products.hpp) is used
// through them instead: one batched product per stage for all k vectors, O(k n) numbers per state, no matrix
// formed and none counted in hessian_evaluations().
//
// A model with a tangent kernel (ModelWithChinTangentSteps: a plugin's chin_tangent_steps) and Hessian-vector products
// takes whole runs of steps there (step_kernel_n): the same operations inlined in the plugin (chin_tangent_stages.hpp),
// the first-same-as-last gradient kept here as the basic step keeps it.
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/base/hessian_products.hpp"
#include "nonsep/core/kernel/chin_tangent_stages.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"

namespace nonsep {

// Hessian evaluations performed by a tangent stepper, counted per state as EvaluationCounts counts gradients.
struct HessianCounts {
  std::uint64_t hessian_T = 0;
  std::uint64_t hessian_V = 0;
  std::uint64_t hessian_K = 0;  // the separable part's flows (tangent_separable_composition.hpp)
  std::uint64_t hessian_U = 0;
  std::uint64_t hvp_H = 0;  // directional derivatives of grad H, per tangent vector (the comparators' tangent maps)
  friend bool operator==(const HessianCounts&, const HessianCounts&) = default;
};

// Throws InvalidArgument unless `tangents` holds k = tangents.count() / x.count() vectors per state of x, with
// 1 <= k <= 2n, of the states' dimension. Returns k.
inline std::size_t check_tangents_fit(const PhaseSpaceBatch& x, const PhaseSpaceBatch& tangents) {
  const std::size_t count = x.count(), n = x.dimension();
  if (tangents.dimension() != n)
    throw InvalidArgument("tangent vectors have dimension " + std::to_string(tangents.dimension()) +
                          " but the states have dimension " + std::to_string(n));
  if (count == 0 || tangents.count() % count != 0 || tangents.count() == 0 || tangents.count() / count > 2 * n)
    throw InvalidArgument("a batch of " + std::to_string(count) + " states of dimension " + std::to_string(n) +
                          " needs k tangent vectors per state, 1 <= k <= " + std::to_string(2 * n) + " (found " +
                          std::to_string(tangents.count()) + " vectors in all)");
  return tangents.count() / count;
}

class TangentBasicStep {
 public:
  explicit TangentBasicStep(ChinBasicStep base = ChinBasicStep()) : base_(std::move(base)) {}

  const ChinBasicStep& base() const { return base_; }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  const HessianCounts& hessian_evaluations() const { return hessians_; }

  // Advances x by `n` times the schedule `dts` of basic steps with the tangent vectors mapped along, in one call of the
  // model's tangent kernel; bit for bit that many calls of step() for a kernel compiled as the evaluation path. Returns
  // false, having changed nothing, when the model has no tangent kernel at hand or no Hessian-vector products (the
  // caller then calls step()). Throws as step() does; after a model exception x and tangents are unspecified.
  template <ModelWithHessians M>
  bool step_kernel_n(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, std::span<const double> dts,
                     std::uint64_t n) {
    if constexpr (!ModelWithChinTangentSteps<M> || !ModelWithHessianProducts<M>) {
      return false;
    } else {
      if (!has_hessian_products(model)) return false;
      const std::size_t k = check_tangents_fit(x, tangents);
      return base_.step_schedule_by(model, x, dts, n, [&](const ChinStepsCall& call) {
        return model.chin_tangent_steps(ChinTangentStepsCall{call, k, tangents.q(), tangents.p()});
      });
    }
  }

  // Advances the states of x by dt as ChinBasicStep::step does, and maps their tangent vectors (layout above)
  // by the step's derivative. Throws InvalidArgument on a bad dt, a batch whose dimension differs from the
  // model's, or tangents that do not fit x; propagates the model's exceptions (x and tangents are then
  // unspecified but valid).
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    const std::size_t k = check_tangents_fit(x, tangents);
    base_.step(model, x, dt, [&](const FlowStage& stage, std::span<const double> eps, const PhaseSpaceBatch& at) {
      apply(model, stage, eps, at, tangents, k);
    });
  }

 private:
  // One Hessian and the point it was evaluated at.
  struct CachedHessian {
    std::vector<double> at, hessian;
  };

  template <ModelWithHessians M>
  void apply(const M& model, const FlowStage& stage, std::span<const double> eps, const PhaseSpaceBatch& x,
             PhaseSpaceBatch& tangents, std::size_t k) {
    const std::size_t count = x.count(), n = x.dimension();
    const std::span<const double> point = stage.kick ? x.q() : x.p();
    // kick: dp += h Hess V(q) dq with h = -c eps; drift: dq += h Hess T(p) dp with h = c eps.
    double* changed = (stage.kick ? tangents.p() : tangents.q()).data();
    const double* driver = (stage.kick ? std::as_const(tangents).q() : std::as_const(tangents).p()).data();
    const double sign = stage.kick ? -1.0 : 1.0;
    if constexpr (ModelWithHessianProducts<M>) {
      if (has_hessian_products(model)) {
        const std::span<const double> products = tangent_hessian_products(
            model, stage.kick, point, count, k, std::span<const double>(driver, count * k * n), products_);
        for (std::size_t b = 0; b < count; ++b) {
          const double h = sign * stage.coefficient * eps[eps.size() == 1 ? 0 : b];
          for (std::size_t i = b * k * n; i < (b + 1) * k * n; ++i) changed[i] += h * products[i];
        }
        return;
      }
    }
    const double* hessian = hessian_at(model, stage.kick, point, count).data();
    for (std::size_t b = 0; b < count; ++b) {
      const double h = sign * stage.coefficient * eps[eps.size() == 1 ? 0 : b];
      const double* matrix = hessian + b * n * n;
      for (std::size_t j = 0; j < k; ++j) {
        const double* in = driver + (b * k + j) * n;
        double* out = changed + (b * k + j) * n;
        for (std::size_t r = 0; r < n; ++r) {
          double sum = 0.0;
          for (std::size_t c = 0; c < n; ++c) sum += matrix[r * n + c] * in[c];
          out[r] += h * sum;
        }
      }
    }
  }

  // Hess V(q) (potential) or Hess T(p) at `point`, evaluated unless the cache holds that point bit for bit.
  template <ModelWithHessians M>
  const std::vector<double>& hessian_at(const M& model, bool potential, std::span<const double> point,
                                        std::size_t count) {
    CachedHessian& cache = potential ? potential_ : kinetic_;
    const std::size_t n = point.size() / count;
    if (cache.at.size() == point.size() &&
        std::memcmp(cache.at.data(), point.data(), point.size() * sizeof(double)) == 0)
      return cache.hessian;
    cache.at.clear();  // a model that throws below leaves no stale cache behind
    cache.hessian.resize(point.size() * n);
    if (potential) {
      model.hessian_V(point, std::span<double>(cache.hessian), count);
      hessians_.hessian_V += count;
    } else {
      model.hessian_T(point, std::span<double>(cache.hessian), count);
      hessians_.hessian_T += count;
    }
    cache.at.assign(point.begin(), point.end());
    return cache.hessian;
  }

  ChinBasicStep base_;
  HessianCounts hessians_;
  CachedHessian potential_, kinetic_;
  HessianProductScratch products_;
};

}  // namespace nonsep
