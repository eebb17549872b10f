#pragma once
// How the schemes of the family "comparator" (Tao's extended phase space, Gauss-Legendre collocation) describe
// themselves. IntegratorDescription (integrator_description.hpp) is shaped for Chin's family: a fractional order, a
// count of basic steps and t2. These schemes differ in kind: they need the full gradient of H
// (hamiltonian_gradient.hpp), one of them iterates, the other is symplectic only on a doubled phase space. So they
// describe themselves here, and integrator_description() gives the common part for a run's summary.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/schemes/integrator_description.hpp"

namespace nonsep {

struct ComparatorDescription {
  std::string scheme;     // "tao", "gauss"
  std::string method;     // human name
  std::string reference;  // where the method comes from
  int order = 2;
  bool symplectic = true;
  bool time_reversible = true;
  std::string properties;  // on which space symplectic, what time-reversible means here
  // Evaluation cost per state, in full gradients of H (EvaluationCounts::grad_H): a fixed number per step of a run
  // (after a first step that may cost more), plus a number per fixed-point iteration for implicit schemes.
  std::uint64_t grad_H_per_step = 0;
  std::uint64_t grad_H_per_iteration = 0;
  std::string cost;  // the same in words, with the first-step and iteration details
  std::vector<std::pair<std::string, double>> parameters;  // name, value: "omega", "max_iterations"

  // The common part, as IntegratorDescription has it (t2 = 0, basic_steps_per_step = 1: neither applies).
  IntegratorDescription integrator_description() const {
    return {scheme, Fraction(order), symplectic, time_reversible, 1, 0.0, "comparator"};
  }
};

}  // namespace nonsep
