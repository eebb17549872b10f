#pragma once
// A runtime-chosen integrator: one of the schemes of the catalogue (integrator_description.hpp), built from a
// scheme name, an order, t2 and the Hamiltonian form. This is what the host builds from a job file; code that
// knows its method at compile time uses ChinBasicStep, TripletComposition or MultiProductExpansion directly.
#include <algorithm>
#include <cstring>
#include <span>
#include <string>
#include <variant>

#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/core/multi_product_expansion.hpp"
#include "nonsep/core/triplet_composition.hpp"

namespace nonsep {

struct IntegratorSpec {
  std::string scheme = "basic";  // "basic", "triplet", "mpe"
  Fraction order = Fraction(2, 3);
  double t2 = ChinCoefficients::default_t2();
  HamiltonianForm form = HamiltonianForm::TTV;
};

class Integrator {
 public:
  // Throws InvalidArgument naming the problem: unknown scheme (listing the known ones), an order the scheme
  // does not have (listing the valid ones), t2 zero or not finite.
  explicit Integrator(const IntegratorSpec& spec);

  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    std::visit([&](auto& stepper) { stepper.step(model, x, dt); }, stepper_);
  }
  const EvaluationCounts& evaluations() const {
    return std::visit([](const auto& stepper) -> const EvaluationCounts& { return stepper.evaluations(); },
                      stepper_);
  }
  IntegratorDescription describe() const {
    return std::visit([](const auto& stepper) { return stepper.describe(); }, stepper_);
  }
  HamiltonianForm form() const { return form_; }
  const IntegratorSpec& spec() const { return spec_; }

  // The first-same-as-last cache, for running steps in another copy of this integrator (the fused plugin path,
  // plugin_abi.h integrate) and carrying on here as if they had been run here. export_cache copies the cached
  // outer gradient into `gradient` (x.q().size() entries) and returns true when it belongs to x's current point
  // (q in TTV, p in VVT, bit for bit); otherwise returns false and leaves `gradient` alone. import_cache makes
  // `gradient` the cached gradient at x's current point, or clears the cache when `valid` is false. A stepper
  // whose cache belongs to another point evaluates anew, as one without a cache does, so export, import and
  // stepping on give the numbers and evaluation counts of stepping on here.
  bool export_cache(const PhaseSpaceBatch& x, std::span<double> gradient) const {
    return std::visit(
        [&](const auto& stepper) {
          const auto cache = stepper.save_cache();
          const std::span<const double> inner = form_ == HamiltonianForm::TTV ? x.q() : x.p();
          if (cache.at.size() != inner.size() || cache.gradient.size() != inner.size() ||
              gradient.size() != inner.size() ||
              std::memcmp(cache.at.data(), inner.data(), inner.size() * sizeof(double)) != 0)
            return false;
          std::copy(cache.gradient.begin(), cache.gradient.end(), gradient.begin());
          return true;
        },
        stepper_);
  }
  void import_cache(const PhaseSpaceBatch& x, std::span<const double> gradient, bool valid) {
    std::visit(
        [&](auto& stepper) {
          ChinBasicStep::Cache cache;
          if (valid) {
            const std::span<const double> inner = form_ == HamiltonianForm::TTV ? x.q() : x.p();
            cache.at.assign(inner.begin(), inner.end());
            cache.gradient.assign(gradient.begin(), gradient.end());
          }
          stepper.restore_cache(cache);
        },
        stepper_);
  }
  // Adds evaluations made elsewhere on this integrator's behalf (with export_cache and import_cache).
  void add_evaluations(const EvaluationCounts& counts) {
    std::visit([&](auto& stepper) { stepper.add_evaluations(counts); }, stepper_);
  }

 private:
  IntegratorSpec spec_;
  HamiltonianForm form_;
  std::variant<ChinBasicStep, TripletComposition<ChinBasicStep>, MultiProductExpansion<ChinBasicStep>> stepper_;
};

}  // namespace nonsep
