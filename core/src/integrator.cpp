#include "nonsep/core/integrator.hpp"

namespace nonsep {

namespace {
std::string known_schemes() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "" : ", ") + scheme.name;
  return list;
}
}  // namespace

Integrator::Integrator(const IntegratorSpec& spec)
    : spec_(spec), form_(spec.form), stepper_(ChinBasicStep(spec.form, spec.t2)) {
  ChinBasicStep base(spec.form, spec.t2);
  if (spec.scheme == "basic") {
    chin_order_index(spec.order, 1, "basic");
  } else if (spec.scheme == "triplet") {
    stepper_ = TripletComposition<>::for_order(base, spec.order);
  } else if (spec.scheme == "mpe") {
    stepper_ = MultiProductExpansion<>::for_order(base, spec.order);
  } else {
    throw InvalidArgument("unknown integrator scheme '" + spec.scheme + "'; the schemes are " + known_schemes());
  }
}

}  // namespace nonsep
