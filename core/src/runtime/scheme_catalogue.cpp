// The scheme catalogue (scheme_catalogue.hpp): the shipped schemes' descriptions, in list order.
#include "nonsep/core/runtime/scheme_catalogue.hpp"

#include "nonsep/core/runtime/integrator.hpp"

namespace nonsep {

std::span<const Scheme> scheme_catalogue() { return Integrator::catalogue(); }

const Scheme* find_scheme(const std::string& name) {
  for (const auto& scheme : scheme_catalogue())
    if (scheme.name == name) return &scheme;
  return nullptr;
}

bool is_comparator(const std::string& name) {
  const Scheme* scheme = find_scheme(name);
  return scheme != nullptr && scheme->family == "comparator";
}

}  // namespace nonsep
