#pragma once
// A runtime-chosen integrator: one of the schemes of the catalogue (integrator_description.hpp), built from a
// scheme name, an order, t2 and the Hamiltonian form. This is what the host builds from a job file; code that
// knows its method at compile time uses ChinBasicStep, TripletComposition or MultiProductExpansion directly.
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

 private:
  IntegratorSpec spec_;
  HamiltonianForm form_;
  std::variant<ChinBasicStep, TripletComposition<ChinBasicStep>, MultiProductExpansion<ChinBasicStep>> stepper_;
};

}  // namespace nonsep
