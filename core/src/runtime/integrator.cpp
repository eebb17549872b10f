#include "nonsep/core/runtime/integrator.hpp"

#include <charconv>
#include <stdexcept>

namespace nonsep {

OptionValue default_option_value(const ParameterDescription& parameter) {
  if (parameter.kind == ParameterDescription::Kind::Order) return Fraction::parse(parameter.default_text);
  const auto& text = parameter.default_text;
  double number = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (ec != std::errc() || end != text.data() + text.size())
    throw std::logic_error("catalogue default '" + text + "' of '" + parameter.name + "' is not a number");
  return number;
}

IntegratorSpec default_spec(const Scheme& scheme, HamiltonianForm form) {
  IntegratorSpec spec;
  spec.scheme = scheme.name;
  spec.form = form;
  for (const auto& parameter : scheme.parameters)
    if (!parameter.default_text.empty()) set_option(spec, parameter, default_option_value(parameter));
  return spec;
}

}  // namespace nonsep
