#pragma once
// The scheme catalogue: the one list of Chin's schemes, as REBOUND keeps its integrators in one table. Each entry
// is a SchemeDescription (its id, its options with defaults, its orders and flags: what the job reader accepts and
// what `nonsep --help` and `nonsep schema` print) and the factory that builds its stepper over a basic step.
// Integrator (integrator.hpp) builds from it, TangentIntegrator (tangent_integrator.hpp) from an Integrator.
// Adding a scheme is one entry in scheme_catalogue.cpp; a new stepper type also joins SchemeStepper, and gets a
// tangent_map_of overload in tangent_integrator.hpp.
//
// Two families (SchemeDescription::family): "chin", the paper's splittings of T(p) + V(q), and "comparator",
// Tao's extended phase space (tao_extended_phase_space.hpp) and Gauss-Legendre collocation (gauss_legendre.hpp),
// which integrate H itself from its gradient (hamiltonian_gradient.hpp): they need a model with Hessians and third
// derivatives, and their tangent maps the directional derivative of grad H.
#include <span>
#include <string>
#include <type_traits>
#include <variant>

#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/integrator_description.hpp"
#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/core/schemes/separable_composition.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/core/schemes/triplet_composition.hpp"

namespace nonsep {

// Every stepper type a catalogue entry can build.
// Chin's schemes are built over the basic step with the separable flows of K(p) + U(q) around it
// (separable_composition.hpp), which is the basic step itself for a model without them.
using SchemeStepper = std::variant<SeparableBasicStep, TripletComposition<SeparableBasicStep>,
                                   MultiProductExpansion<SeparableBasicStep>, TaoExtendedPhaseSpace, GaussLegendre>;

// The comparator stepper types: they need ModelWithThirdDerivatives (and their tangent maps the directional
// derivative of grad H, ModelWithHamiltonianHessian).
template <class S>
inline constexpr bool is_comparator_stepper =
    std::is_same_v<S, TaoExtendedPhaseSpace> || std::is_same_v<S, GaussLegendre>;

struct IntegratorSpec;  // integrator.hpp

struct Scheme : SchemeDescription {
  // Builds the stepper the spec describes (its order, t2, omega, stages, ... and form). Throws InvalidArgument
  // naming the option that the scheme refuses (an order it does not have, t2 = 0, omega <= 0, stages 4).
  SchemeStepper (*make)(const IntegratorSpec& spec) = nullptr;
};

// Every scheme the core provides, in a fixed order (basic, triplet, mpe, tao, implicit_midpoint, gauss).
std::span<const Scheme> scheme_catalogue();
// The catalogue entry named `name`, or nullptr.
const Scheme* find_scheme(const std::string& name);

}  // namespace nonsep
