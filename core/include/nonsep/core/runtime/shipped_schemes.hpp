#pragma once
// The one list of the schemes the core ships, in catalogue order: Integrator, IntegratorSpec (integrator.hpp) and
// TangentIntegrator (tangent_integrator.hpp) are the basic templates over it. Adding a scheme: its header (stepper,
// options, scheme type: stepper.hpp), its tangent header (tangent stepper and tangent_map_of) and a line here.
#include "nonsep/core/schemes/chin_schemes.hpp"
#include "nonsep/core/schemes/comparator_schemes.hpp"
#include "nonsep/core/tangent/tangent_gauss_legendre.hpp"
#include "nonsep/core/tangent/tangent_multi_product_expansion.hpp"
#include "nonsep/core/tangent/tangent_separable_composition.hpp"
#include "nonsep/core/tangent/tangent_tao_extended_phase_space.hpp"
#include "nonsep/core/tangent/tangent_triplet_composition.hpp"

namespace nonsep {

// T<the shipped schemes..., Extra...>: basic, triplet, mpe, tao, implicit_midpoint, gauss, then any schemes a user
// (or a test) adds to them.
template <template <class...> class T, class... Extra>
using WithShippedSchemes = T<BasicScheme, TripletScheme, MultiProductExpansionScheme, TaoScheme, ImplicitMidpointScheme,
                             GaussScheme, Extra...>;

}  // namespace nonsep
