#pragma once
// The runtime-chosen integrator of the shipped schemes (shipped_schemes.hpp): one of the catalogue's schemes
// (scheme_catalogue.hpp), built from a scheme name, its options and the Hamiltonian form (BasicIntegrator,
// basic_integrator.hpp). This is what the host builds from a job file; code that knows its method at compile time
// uses ChinBasicStep, TripletComposition, MultiProductExpansion, TaoExtendedPhaseSpace or GaussLegendre directly.
//
// Comparators (family "comparator") need ModelWithThirdDerivatives: stepping one with a model type without them
// throws InvalidArgument (the host refuses such jobs before running).
#include "nonsep/core/runtime/basic_integrator.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/core/runtime/shipped_schemes.hpp"

namespace nonsep {

// The scheme's name, its options (ChinOptions, TaoOptions, ImplicitMidpointOptions, GaussOptions) and the form:
// IntegratorSpec{"triplet", ChinOptions{Fraction(2)}}. The job reader sets options by their catalogue names
// (set_option), the host's checkpoint fingerprint and summaries read every option of a scheme (option_value).
using IntegratorSpec = WithShippedSchemes<BasicIntegratorSpec>;
using Integrator = WithShippedSchemes<BasicIntegrator>;
// Every stepper type a shipped scheme builds.
using SchemeStepper = Integrator::Stepper;

// The spec of `scheme` with every option at its catalogue default (required options, without one, at their
// Options{} values), in form `form`.
IntegratorSpec default_spec(const Scheme& scheme, HamiltonianForm form = HamiltonianForm::TTV);
// The spec of `scheme` of order `order`, its other options at their defaults: the option "order" set to it, or
// "stages" to order / 2 (Gauss-Legendre). InvalidArgument naming the scheme's orders when it has not this one.
IntegratorSpec spec_of_order(const Scheme& scheme, const Fraction& order, HamiltonianForm form = HamiltonianForm::TTV);

}  // namespace nonsep
