#pragma once
// The scheme catalogue: the shipped schemes' descriptions (SchemeDescription: each one's id, its options with
// defaults, its orders and flags: what the job reader accepts and what `nonsep --help` and `nonsep schema` print), as
// REBOUND keeps its integrators in one table. Each scheme type describes itself (stepper.hpp); the list is
// shipped_schemes.hpp, and Integrator (integrator.hpp) builds from it.
//
// Two families (SchemeDescription::family): "chin", the paper's splittings of T(p) + V(q), and "comparator",
// Tao's extended phase space (tao_extended_phase_space.hpp) and Gauss-Legendre collocation (gauss_legendre.hpp),
// which integrate H itself from its gradient (hamiltonian_gradient.hpp): they need a model with Hessians and third
// derivatives, and their tangent maps the directional derivative of grad H.
#include <span>
#include <string>

#include "nonsep/core/schemes/integrator_description.hpp"

namespace nonsep {

// A catalogue entry.
using Scheme = SchemeDescription;

// Every scheme the core provides, in a fixed order (basic, triplet, mpe, tao, implicit_midpoint, gauss).
std::span<const Scheme> scheme_catalogue();
// The catalogue entry named `name`, or nullptr.
const Scheme* find_scheme(const std::string& name);
// Whether the scheme named `name` is of the family "comparator" (it integrates H from its gradient), read from the
// catalogue without building it; false for a name the catalogue lacks.
bool is_comparator(const std::string& name);

}  // namespace nonsep
