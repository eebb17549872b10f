#include "nonsep/core/integrator.hpp"

namespace nonsep {

namespace {
std::string known_schemes() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "" : ", ") + scheme.name;
  return list;
}

SchemeStepper build(const IntegratorSpec& spec) {
  ChinBasicStep base(spec.form, spec.t2);
  const Scheme* scheme = find_scheme(spec.scheme);
  if (!scheme)
    throw InvalidArgument("unknown integrator scheme '" + spec.scheme + "'; the schemes are " + known_schemes());
  return scheme->make(std::move(base), chin_order_index(spec.order, scheme->highest_order_index, scheme->name));
}
}  // namespace

Integrator::Integrator(const IntegratorSpec& spec) : spec_(spec), form_(spec.form), stepper_(build(spec)) {}

}  // namespace nonsep
