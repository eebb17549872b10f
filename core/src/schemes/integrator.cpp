#include "nonsep/core/schemes/integrator.hpp"

#include <charconv>
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

std::variant<Fraction, double> option_value(const IntegratorSpec& spec, const ParameterDescription& parameter) {
  IntegratorSpec copy = spec;  // option_field hands out fields to write; here they are only read
  return std::visit([](auto* field) -> std::variant<Fraction, double> { return *field; },
                    option_field(copy, parameter));
}

std::variant<Fraction, double> default_option_value(const ParameterDescription& parameter) {
  if (parameter.kind == ParameterDescription::Kind::Order) return Fraction::parse(parameter.default_text);
  const auto& text = parameter.default_text;
  double number = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (ec != std::errc() || end != text.data() + text.size())
    throw std::logic_error("catalogue default '" + text + "' of '" + parameter.name + "' is not a number");
  return number;
}

void set_option(IntegratorSpec& spec, const ParameterDescription& parameter,
                const std::variant<Fraction, double>& value) {
  std::visit(
      [&](auto* field) {
        using Field = std::remove_pointer_t<decltype(field)>;
        const auto* given = std::get_if<Field>(&value);
        if (!given) throw std::logic_error("option '" + parameter.name + "' set with a value of the other kind");
        *field = *given;
      },
      option_field(spec, parameter));
}

IntegratorSpec default_spec(const Scheme& scheme, HamiltonianForm form) {
  IntegratorSpec spec;
  spec.scheme = scheme.name;
  spec.form = form;
  for (const auto& parameter : scheme.parameters)
    if (!parameter.default_text.empty()) set_option(spec, parameter, default_option_value(parameter));
  return spec;
}

Integrator::Integrator(const IntegratorSpec& spec) : spec_(spec), form_(spec.form), stepper_(build(spec)) {}

IntegratorDescription Integrator::describe() const {
  IntegratorDescription d = std::visit([](const auto& stepper) { return description_of(stepper); }, stepper_);
  d.scheme = spec_.scheme;  // one stepper type serves two entries (gauss, implicit_midpoint): the entry's name
  return d;
}

std::string Integrator::needs_third_derivatives() const {
  return "the comparator scheme '" + spec_.scheme +
         "' integrates H from its gradient and needs a model with Hessians (hessian_T, hessian_V) and third "
         "derivatives (d3T, d3V); use a Chin scheme (basic, triplet, mpe) with this model";
}

}  // namespace nonsep
