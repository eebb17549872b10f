#pragma once
// A runtime-chosen integrator: one of the schemes of the catalogue (scheme_catalogue.hpp), built by the entry's
// factory from a scheme name, an order, t2 and the Hamiltonian form. This is what the host builds from a job file;
// code that knows its method at compile time uses ChinBasicStep, TripletComposition or MultiProductExpansion
// directly.
#include <string>
#include <variant>

#include "nonsep/core/scheme_catalogue.hpp"

namespace nonsep {

struct IntegratorSpec {
  std::string scheme = "basic";  // a catalogue entry's name: "basic", "triplet", "mpe"
  Fraction order = Fraction(2, 3);
  double t2 = ChinCoefficients::default_t2();
  HamiltonianForm form = HamiltonianForm::TTV;
};

class Integrator {
 public:
  // Throws InvalidArgument naming the problem: t2 zero or not finite, unknown scheme (listing the known ones), an
  // order the scheme does not have (listing the valid ones), checked in that order.
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
  // The stepper the catalogue entry built (TangentIntegrator maps it to its tangent map).
  const SchemeStepper& stepper() const { return stepper_; }

 private:
  IntegratorSpec spec_;
  HamiltonianForm form_;
  SchemeStepper stepper_;
};

}  // namespace nonsep
