#pragma once
// The scheme catalogue: the one list of Chin's schemes, as REBOUND keeps its integrators in one table. Each entry
// is a SchemeDescription (its id, its options with defaults, its orders and flags: what the job reader accepts and
// what `nonsep --help` and `nonsep schema` print) and the factory that builds its stepper over a basic step.
// Integrator (integrator.hpp) builds from it, TangentIntegrator (tangent_integrator.hpp) from an Integrator.
// Adding a scheme is one entry in scheme_catalogue.cpp; a new stepper type also joins SchemeStepper, and gets a
// tangent_map_of overload in tangent_integrator.hpp (without one the tangent integrator does not compile).
#include <span>
#include <string>
#include <variant>

#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/core/integrator_description.hpp"
#include "nonsep/core/multi_product_expansion.hpp"
#include "nonsep/core/triplet_composition.hpp"

namespace nonsep {

// Every stepper type a catalogue entry can build.
using SchemeStepper =
    std::variant<ChinBasicStep, TripletComposition<ChinBasicStep>, MultiProductExpansion<ChinBasicStep>>;

struct Scheme : SchemeDescription {
  // Builds the stepper of order 2j/3 over `base`, j = order_index in [1, highest_order_index] (checked by the
  // caller, Integrator, with chin_order_index).
  SchemeStepper (*make)(ChinBasicStep base, int order_index) = nullptr;
};

// Every scheme the core provides, in a fixed order (basic, triplet, mpe).
std::span<const Scheme> scheme_catalogue();
// The catalogue entry named `name`, or nullptr.
const Scheme* find_scheme(const std::string& name);

}  // namespace nonsep
