#pragma once
// A scheme's options: one struct per scheme with typed members (ChinOptions, TaoOptions, GaussOptions, ...), each
// naming its members as the catalogue names the options (ParameterDescription::name), so that a reader that knows
// only the names (the job reader, a checkpoint's fingerprint, a summary) sets and reads them:
//
//   struct TaoOptions {
//     Fraction order = Fraction(2);
//     double omega = 20.0;
//     static constexpr auto members() {
//       return std::tuple{option("order", &TaoOptions::order), option("omega", &TaoOptions::omega, "binding ...")};
//     }
//   };
//
// Members are Fraction (an order), double or int. A job file gives an order as a Fraction and every other option as
// a number (OptionValue); an int member takes only a whole number. Each option's name, default and description are
// written there once: the catalogue's entries (ParameterDescription) are made from them by describe_options, with
// the defaults of the scheme (a scheme type's defaults(), or its Options as constructed: scheme_defaults in
// stepper.hpp).
#include <cmath>
#include <concepts>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <variant>
#include <vector>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/fraction.hpp"
#include "nonsep/core/schemes/integrator_description.hpp"

namespace nonsep {

// An option's value as a job file gives it: a Fraction for an order, a number otherwise.
using OptionValue = std::variant<Fraction, double>;

// One member of an options struct: its catalogue name, what the catalogue says of it (an order's words come from its
// scheme: describe_options), and whether it must not be 0 (t2: the scheme refuses 0 when it is built, the schema
// states it).
// Its range, when it has one, is declared with it (option(...).within(1, 8), .at_least(1), .above(0)): the catalogue
// and the job schema state it, and the host's tests hold the scheme to it (the scheme's own check refuses a value
// outside it with its own words).
template <class Options, class T>
struct OptionMember {
  const char* name;
  T Options::*member;
  const char* description;
  bool nonzero;
  double minimum;
  double maximum;
  bool minimum_exclusive;
  constexpr OptionMember within(double low, double high) const {
    return {name, member, description, nonzero, low, high, false};
  }
  constexpr OptionMember at_least(double low) const {
    return {name, member, description, nonzero, low, maximum, false};
  }
  constexpr OptionMember above(double low) const { return {name, member, description, nonzero, low, maximum, true}; }
};
template <class Options, class T>
constexpr OptionMember<Options, T> option(const char* name, T Options::*member, const char* description = "",
                                          bool nonzero = false) {
  return {name,
          member,
          description,
          nonzero,
          -std::numeric_limits<double>::infinity(),
          std::numeric_limits<double>::infinity(),
          false};
}

template <class O>
concept SchemeOptions = std::default_initializable<O> && std::copyable<O> && requires {
  O::members();
};

// `value` as an int option `name`, or InvalidArgument naming it when it is not a whole number.
inline int whole_number(double value, const std::string& name) {
  if (!std::isfinite(value) || value != std::floor(value) || std::abs(value) > 1e9)
    throw InvalidArgument(name + " must be a whole number (found " + found_number(value) + ")");
  return static_cast<int>(value);
}

// Calls f(member) for the member of `options` named `name`; std::logic_error when there is none (a programming
// error: the catalogue entry names an option its options struct lacks; the host's tests read every option).
template <SchemeOptions O, class F>
void with_option_member(O& options, const std::string& name, F&& f) {
  bool found = false;
  std::apply(
      [&](const auto&... members) {
        ((!found && name == members.name ? (f(options.*members.member), found = true) : false), ...);
      },
      O::members());
  if (!found)
    throw std::logic_error("the options of this scheme have no member for the catalogue option '" + name + "'");
}

// The option `name` of `options`, as a job file would give it (an int as a double).
template <SchemeOptions O>
OptionValue read_option(const O& options, const std::string& name) {
  OptionValue value;
  O copy = options;  // with_option_member hands out members to write; here they are only read
  with_option_member(copy, name, [&](const auto& member) {
    if constexpr (std::is_same_v<std::decay_t<decltype(member)>, Fraction>)
      value = member;
    else
      value = static_cast<double>(member);
  });
  return value;
}

// Sets option `name` of `options` to `value`: a Fraction for a Fraction member, a number otherwise
// (std::logic_error for the other kind; InvalidArgument for an int member and a number that is not whole).
template <SchemeOptions O>
void write_option(O& options, const std::string& name, const OptionValue& value) {
  with_option_member(options, name, [&](auto& member) {
    using T = std::decay_t<decltype(member)>;
    if constexpr (std::is_same_v<T, Fraction>) {
      if (const auto* given = std::get_if<Fraction>(&value)) return void(member = *given);
    } else if (const auto* given = std::get_if<double>(&value)) {
      if constexpr (std::is_same_v<T, int>)
        member = whole_number(*given, name);
      else
        member = *given;
      return;
    }
    throw std::logic_error("option '" + name + "' set with a value of the other kind");
  });
}

// The catalogue's entries for the options of `defaults`' type, in members() order: each member's name, its kind
// (Order for a Fraction, Number otherwise), its default (its value in `defaults`, as a job file writes it: "4/3",
// "-1.8171205928321397", "20") and its description; an order's description is "order of convergence as an exact
// fraction; " followed by `orders`, the scheme's words for the orders it has.
template <SchemeOptions O>
std::vector<ParameterDescription> describe_options(const O& defaults, const std::string& orders = "") {
  std::vector<ParameterDescription> parameters;
  std::apply(
      [&](const auto&... members) {
        (
            [&](const auto& m) {
              using T = std::decay_t<decltype(defaults.*m.member)>;
              const T& value = defaults.*m.member;
              ParameterDescription parameter{m.name,
                                             ParameterDescription::Kind::Number,
                                             "",
                                             m.description,
                                             m.nonzero,
                                             std::is_same_v<T, int>,
                                             m.minimum,
                                             m.maximum,
                                             m.minimum_exclusive};
              if constexpr (std::is_same_v<T, Fraction>) {
                parameter.kind = ParameterDescription::Kind::Order;
                parameter.default_text = value.to_string();
                parameter.description = "order of convergence as an exact fraction; " + orders;
              } else if constexpr (std::is_same_v<T, int>) {
                parameter.default_text = std::to_string(value);
              } else {
                char text[32];
                std::snprintf(text, sizeof text, "%.17g", value);
                parameter.default_text = text;
              }
              parameters.push_back(std::move(parameter));
            }(members),
            ...);
      },
      O::members());
  return parameters;
}

}  // namespace nonsep
