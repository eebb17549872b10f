#include "nonsep/core/runtime/integrator.hpp"

#include <algorithm>
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

IntegratorSpec spec_of_order(const Scheme& scheme, const Fraction& order, HamiltonianForm form) {
  IntegratorSpec spec = default_spec(scheme, form);
  const auto orders = scheme.orders();
  if (std::find(orders.begin(), orders.end(), order) == orders.end()) {
    std::string known;
    for (const Fraction& o : orders) known += (known.empty() ? "" : ", ") + o.to_string();
    throw InvalidArgument("the scheme '" + scheme.name + "' has no order " + order.to_string() + "; its orders are " +
                          known);
  }
  for (const auto& parameter : scheme.parameters) {
    if (parameter.name == "order") set_option(spec, parameter, order);
    if (parameter.name == "stages") set_option(spec, parameter, order.value() / 2.0);
  }
  if (Integrator::describe(spec).order != order)
    throw std::logic_error("the catalogue entry '" + scheme.name + "' lists order " + order.to_string() +
                           " but no option sets it");
  return spec;
}

}  // namespace nonsep
