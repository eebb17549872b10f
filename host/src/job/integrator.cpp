// /hamiltonian and /integrator: the scheme and its options, read against the core's catalogue
// (nonsep::scheme_catalogue()); whether an option's value is valid is decided by the core, by building the scheme.
#include "nonsep/core/runtime/integrator.hpp"

#include <algorithm>
#include <stdexcept>
#include <variant>

#include "job_keys.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/host/number_format.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

std::string scheme_names() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "\"" : ", \"") + scheme.name + "\"";
  return list;
}

// The value of one catalogue parameter, as the job wrote it or as its default: a Fraction for the order, a double
// otherwise (nonsep::set_option).

std::optional<OptionValue> read_option(Checker& check, const ParameterDescription& parameter, const json& value,
                                       const std::string& path) {
  if (parameter.kind == ParameterDescription::Kind::Number) {
    const auto x = check.finite_number(value, path, "a finite number: " + parameter.description);
    if (!x) return std::nullopt;
    return OptionValue(*x);
  }
  try {
    if (value.is_string()) return OptionValue(Fraction::parse(value.get<std::string>()));
    if (const auto integral = integral_value(value)) return OptionValue(Fraction(*integral));
  } catch (const InvalidArgument&) {
  }
  check.issue(path, describe(value),
              "an exact fraction as a string (\"4/3\") or an integer (2): " + parameter.description);
  return std::nullopt;
}

// The options of the scheme, or with an unknown scheme the options of every scheme (so that their problems are
// reported too).
std::vector<ParameterDescription> options_of(const Scheme* scheme) {
  if (scheme) return scheme->parameters;
  std::vector<ParameterDescription> parameters;
  for (const auto& entry : scheme_catalogue())
    for (const auto& parameter : entry.parameters)
      if (std::none_of(parameters.begin(), parameters.end(),
                       [&](const ParameterDescription& known) { return known.name == parameter.name; }))
        parameters.push_back(parameter);
  return parameters;
}

}  // namespace

HamiltonianForm read_hamiltonian(const KeyReader& document) {
  if (const auto form = document.string("hamiltonian"))
    for (const auto& [name, value] : hamiltonian_forms())
      if (*form == name) return value;
  return HamiltonianForm::TTV;
}

IntegratorSpec read_integrator_object(Checker& check, const json& integrator, const std::string& path,
                                      HamiltonianForm form, const std::vector<std::string>& extra_keys) {
  IntegratorSpec spec;
  spec.form = form;
  const Scheme* scheme = nullptr;
  if (const json* name = check.member(integrator, path, "scheme", true, "one of " + scheme_names())) {
    if (name->is_string()) scheme = find_scheme(name->get<std::string>());
    if (scheme)
      spec.scheme = scheme->name;
    else
      check.issue(child(path, "scheme"), describe(*name), "one of " + scheme_names());
  }
  const std::vector<ParameterDescription> parameters = options_of(scheme);
  std::vector<std::string> keys{"scheme"};
  for (const auto& parameter : parameters) keys.push_back(parameter.name);
  keys.insert(keys.end(), extra_keys.begin(), extra_keys.end());
  check.known_keys(integrator, path, keys);

  // Every option starts at the scheme's default, so that a refused value leaves a spec the scheme can build (a
  // comparator refuses IntegratorSpec's own default order 2/3).
  if (scheme)
    for (const auto& parameter : parameters)
      if (!parameter.default_text.empty()) set_option(spec, parameter, default_option_value(parameter));
  for (const auto& parameter : parameters) {
    const std::string option_path = child(path, parameter.name);
    const json* given =
        check.member(integrator, path, parameter.name, parameter.default_text.empty(), parameter.description);
    if (!given) {
      if (scheme && !parameter.default_text.empty()) set_option(spec, parameter, default_option_value(parameter));
      continue;
    }
    const auto value = read_option(check, parameter, *given, option_path);
    if (!value || !scheme) continue;
    // The core decides what is valid: the scheme described with this one option set and the others at their
    // defaults (setting an integer option refuses a number that is not whole).
    IntegratorSpec probe{scheme->name, {}, spec.form};
    for (const auto& other : parameters)
      if (!other.default_text.empty()) set_option(probe, other, default_option_value(other));
    try {
      set_option(probe, parameter, *value);
      Integrator::describe(probe);
      set_option(spec, parameter, *value);
    } catch (const InvalidArgument& error) {
      check.issue(option_path, describe(*given), error.what());
    }
  }
  return spec;
}

IntegratorSpec read_integrator(Checker& check, const KeyReader& document, HamiltonianForm form,
                               std::optional<AutoScheme>& auto_scheme) {
  // Required in a run (the table cannot say so: a study refuses it).
  const json* integrator = document.value("integrator");
  if (!integrator)
    check.member(document.object(), "", "integrator", true,
                 "an object with \"scheme\" (" + scheme_names() + " or \"auto\") and options");
  IntegratorSpec spec;
  spec.form = form;
  if (!integrator || !check.object(*integrator, "/integrator", "an object with \"scheme\" and the scheme's options"))
    return spec;
  if (!integrator->contains("scheme") || (*integrator)["scheme"] != "auto")
    return read_integrator_object(check, *integrator, "/integrator", form);
  const KeyTable& keys = auto_integrator_keys();
  std::vector<std::string> names{"scheme"};
  for (const auto& name : keys.names()) names.push_back(name);
  check.known_keys(*integrator, "/integrator", names);
  AutoScheme chosen;
  const std::string range = "a number from " + format_number(auto_tolerance_min) + " to " +
                            format_number(auto_tolerance_max) + ": " + keys["tolerance"].description;
  if (const json* value = check.member(*integrator, "/integrator", "tolerance", true, range))
    if (const auto x = check.finite_number(*value, "/integrator/tolerance", range)) {
      if (*x < auto_tolerance_min || *x > auto_tolerance_max)
        check.issue("/integrator/tolerance", describe(*value), range);
      else
        chosen.tolerance = *x;
    }
  if (const json* value = check.member(*integrator, "/integrator", "measure", false, "")) {
    if (*value == "energy")
      chosen.measure = AutoScheme::Measure::energy;
    else if (*value != "phase")
      check.issue("/integrator/measure", describe(*value),
                  "\"phase\" (the phase-space error at t_end, the default) or \"energy\" (the largest |dH/H0|)");
  }
  auto_scheme = chosen;
  spec.scheme = "triplet";  // a valid spec until the choice replaces it
  spec.options = ChinOptions{Fraction(4, 3)};
  return spec;
}

}  // namespace nonsep::host::job_reader
