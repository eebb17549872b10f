#include "nonsep/core/integrator.hpp"

#include <stdexcept>

namespace nonsep {

namespace {
std::string known_schemes() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "" : ", ") + scheme.name;
  return list;
}

SchemeStepper build(const IntegratorSpec& spec) {
  const Scheme* scheme = find_scheme(spec.scheme);
  // t2 first, as before the comparators joined: it is the one option every Chin scheme has.
  if (!scheme || scheme->family == "chin") ChinBasicStep(spec.form, spec.t2);
  if (!scheme)
    throw InvalidArgument("unknown integrator scheme '" + spec.scheme + "'; the schemes are " + known_schemes());
  return scheme->make(spec);
}

template <class S>
IntegratorDescription description_of(const S& stepper) {
  if constexpr (is_comparator_stepper<S>)
    return stepper.describe().integrator_description();
  else
    return stepper.describe();
}
}  // namespace

OptionField option_field(IntegratorSpec& spec, const ParameterDescription& parameter) {
  const bool number = parameter.kind == ParameterDescription::Kind::Number;
  if (parameter.name == "order" && parameter.kind == ParameterDescription::Kind::Order) return &spec.order;
  if (parameter.name == "t2" && number) return &spec.t2;
  if (parameter.name == "omega" && number) return &spec.omega;
  if (parameter.name == "stages" && number) return &spec.stages;
  if (parameter.name == "max_iterations" && number) return &spec.max_iterations;
  throw std::logic_error("IntegratorSpec has no field for the catalogue option '" + parameter.name + "'");
}

Integrator::Integrator(const IntegratorSpec& spec) : spec_(spec), form_(spec.form), stepper_(build(spec)) {}

IntegratorDescription Integrator::describe() const {
  IntegratorDescription d = std::visit([](const auto& stepper) { return description_of(stepper); }, stepper_);
  d.scheme = spec_.scheme == "implicit_midpoint" ? spec_.scheme : d.scheme;
  return d;
}

std::string Integrator::needs_third_derivatives() const {
  return "the comparator scheme '" + spec_.scheme +
         "' integrates H from its gradient and needs a model with Hessians (hessian_T, hessian_V) and third "
         "derivatives (d3T, d3V); use a Chin scheme (basic, triplet, mpe) with this model";
}

}  // namespace nonsep
