// /hamiltonian and /integrator: the scheme and its options, read against the core's catalogue
// (nonsep::scheme_catalogue()); whether an option's value is valid is decided by the core, by building the scheme.
#include "nonsep/core/runtime/integrator.hpp"

#include <algorithm>
#include <stdexcept>
#include <variant>

#include "job_keys.hpp"
#include "nonsep/core/base/error.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

std::string scheme_names() {
  std::string list;
  for (const auto& scheme : scheme_catalogue()) list += (list.empty() ? "\"" : ", \"") + scheme.name + "\"";
  return list;
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

// The scheme an integrator object names, if the catalogue has it.
const Scheme* named_scheme(const json& integrator) {
  if (!integrator.is_object() || !integrator.contains("scheme") || !integrator["scheme"].is_string()) return nullptr;
  return find_scheme(integrator["scheme"].get<std::string>());
}

// The key table of an integrator object: "scheme", the options the catalogue gives it (an order, or a number whose
// range the core checks), then `extra`'s keys and pairs.
KeyTable integrator_keys(const Scheme* scheme, const KeyTable* extra) {
  KeyTable table;
  // A run's integrator (no extra keys) may also be "auto" (read before this table: read_integrator).
  KeyRule name{.name = "scheme",
               .type = ValueType::choice,
               .required = true,
               .allowed = "one of " + scheme_names() + (extra ? "" : " or \"auto\"")};
  for (const auto& entry : scheme_catalogue()) name.choices.push_back(entry.name);
  table.rules.push_back(std::move(name));
  for (const auto& parameter : options_of(scheme)) {
    const bool order = parameter.kind == ParameterDescription::Kind::Order;
    table.rules.push_back(
        {.name = parameter.name,
         .type = order ? ValueType::order : ValueType::finite,
         .required = parameter.default_text.empty(),
         .allowed = (order ? "an exact fraction as a string (\"4/3\") or an integer (2): " : "a finite number: ") +
                    parameter.description});
  }
  if (extra) {
    table.rules.insert(table.rules.end(), extra->rules.begin(), extra->rules.end());
    table.pairs = extra->pairs;
  }
  return table;
}

// The rule of a core message (error.hpp): the message without the " (found X)" it ends with, for the issue shows the
// value as the job file has it.
std::string rule_of(const std::string& message) {
  const std::size_t found = message.rfind(" (found ");
  return found != std::string::npos && message.back() == ')' ? message.substr(0, found) : message;
}

// The value of one catalogue option as the table checked it: a Fraction for the order, a double otherwise
// (nonsep::set_option).
OptionValue option_value(const ParameterDescription& parameter, const json& value) {
  if (parameter.kind == ParameterDescription::Kind::Number) return OptionValue(value.get<double>());
  return OptionValue(*order_value(value));
}

}  // namespace

IntegratorReader::IntegratorReader(Checker& check, const json& integrator, const std::string& path,
                                   HamiltonianForm form, const KeyTable* extra, const std::string& what)
    : scheme_(named_scheme(integrator)),
      table_(integrator_keys(scheme_, extra)),
      keys_(check, integrator, path, table_, what) {
  spec_.form = form;
  if (!scheme_ || !keys_.is_object()) return;
  spec_.scheme = scheme_->name;
  const std::vector<ParameterDescription>& parameters = scheme_->parameters;
  // Every option starts at the scheme's default, so that a refused value leaves a spec the scheme can build (a
  // comparator refuses IntegratorSpec's own default order 2/3).
  for (const auto& parameter : parameters)
    if (!parameter.default_text.empty()) set_option(spec_, parameter, default_option_value(parameter));
  for (const auto& parameter : parameters) {
    const json* given = keys_.value(parameter.name);
    if (!given) continue;
    const OptionValue value = option_value(parameter, *given);
    // The core decides what is valid: the scheme described with this one option set and the others at their
    // defaults (setting an integer option refuses a number that is not whole).
    IntegratorSpec probe{scheme_->name, {}, spec_.form};
    for (const auto& other : parameters)
      if (!other.default_text.empty()) set_option(probe, other, default_option_value(other));
    try {
      set_option(probe, parameter, value);
      Integrator::describe(probe);
      set_option(spec_, parameter, value);
    } catch (const InvalidArgument& error) {
      check.issue(keys_.path(parameter.name), describe(*given), rule_of(error.what()));
    }
  }
}

HamiltonianForm read_hamiltonian(const KeyReader& document) {
  if (const auto form = document.string("hamiltonian"))
    for (const auto& [name, value] : hamiltonian_forms())
      if (*form == name) return value;
  return HamiltonianForm::TTV;
}

IntegratorSpec read_integrator(Checker& check, const KeyReader& document, HamiltonianForm form,
                               std::optional<AutoScheme>& auto_scheme) {
  // Required in a run (the table cannot say so: a study refuses it).
  const json* integrator = document.value("integrator");
  if (!integrator)
    check.member(document.object(), "", "integrator", true,
                 "an object with \"scheme\" (" + scheme_names() + " or \"auto\") and options");
  const std::string what = "an object with \"scheme\" and the scheme's options";
  if (!integrator || !integrator->is_object() || !integrator->contains("scheme") || (*integrator)["scheme"] != "auto")
    return integrator ? IntegratorReader(check, *integrator, "/integrator", form, nullptr, what).spec()
                      : IntegratorSpec{.form = form};
  KeyTable keys = auto_integrator_keys();
  keys.rules.insert(keys.rules.begin(), {.name = "scheme", .type = ValueType::choice, .choices = {"auto"}});
  const KeyReader reader(check, *integrator, "/integrator", keys, what);
  AutoScheme chosen;
  if (const auto tolerance = reader.number("tolerance")) chosen.tolerance = *tolerance;
  if (reader.string("measure") == "energy") chosen.measure = AutoScheme::Measure::energy;
  auto_scheme = chosen;
  // A valid spec until the choice replaces it.
  return IntegratorSpec{.scheme = "triplet", .options = ChinOptions{Fraction(4, 3)}, .form = form};
}

}  // namespace nonsep::host::job_reader
