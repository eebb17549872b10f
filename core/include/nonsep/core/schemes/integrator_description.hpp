#pragma once
// Integrators describe themselves. A SchemeDescription is what the catalogue (scheme_catalogue.hpp) says about a
// method family: what the JSON reader accepts and what `--help` and `nonsep schema` print; an IntegratorDescription
// describes one configured instance (what a run reports in its summary).
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "nonsep/core/base/fraction.hpp"

namespace nonsep {

struct ParameterDescription {
  enum class Kind { Number, Order };
  std::string name;
  Kind kind = Kind::Number;
  // Default as it would be written in a job file ("-1.8171205928321397", "2/3"). Empty: required.
  std::string default_text;
  std::string description;
  // A Number that must not be 0 (t2). The scheme refuses 0 when it is built; the job schema states it.
  bool nonzero = false;
  // A whole number (stages, max_iterations): the job reader refuses 1.5, the schema says "integer".
  bool integer = false;
  // The range the scheme accepts (stages 1 to 8, omega > 0), as its options declare it (scheme_options.hpp):
  // infinite where there is no bound; minimum_exclusive for a bound the value must exceed.
  double minimum = -std::numeric_limits<double>::infinity();
  double maximum = std::numeric_limits<double>::infinity();
  bool minimum_exclusive = false;
};

struct SchemeDescription {
  std::string name;       // the job file's integrator.scheme: "basic", "triplet", "mpe"
  std::string method;     // human name: "Chin basic 9-stage splitting"
  std::string equations;  // where in the paper: "eq. (expalg)"
  std::string summary;    // one paragraph
  // "chin" (the paper's splittings) or "comparator" (Tao, Gauss-Legendre: they integrate H itself, so they need the
  // gradient of H, i.e. the plugin's Hessians and third derivatives; their tangent maps the directional derivative
  // of grad H). The family says how a scheme works and what it needs of the plugin, not which to prefer.
  std::string family = "chin";
  bool symplectic = true;
  bool time_reversible = true;
  std::vector<ParameterDescription> parameters;
  // The orders the scheme has: 2j/3 for j = 1 .. highest_order_index (basic 1, triplet 13, mpe 16).
  int highest_order_index = 1;
  // A comparator's orders (2, 4, 6) when they are not of the form 2j/3; empty for Chin's schemes.
  std::vector<Fraction> comparator_orders;
  // The orders scheme "auto" tries of this scheme (the host's scheme_choice.hpp), highest first; empty: none. Auto
  // tries the comparators' before Chin's, each by falling order (on paper1d the highest Gauss order needs the fewest
  // grad H to meet 1e-8 or tighter: bench/comparators.cpp).
  std::vector<Fraction> auto_orders;
  std::vector<Fraction> orders() const;
};

struct IntegratorDescription {
  std::string scheme;
  Fraction order;
  bool symplectic = true;
  bool time_reversible = true;
  std::uint64_t basic_steps_per_step = 1;
  double t2 = 0.0;
  std::string family = "chin";
  friend bool operator==(const IntegratorDescription&, const IntegratorDescription&) = default;
};

// Orders of the paper's family are 2j/3, j = 1, 2, 3, ... (2/3, 4/3, 2, 8/3, 10/3, 4, ...).
// Returns j for a valid order; throws InvalidArgument naming the order and listing the valid ones otherwise,
// or if j exceeds `max_j` (the practical limit of a scheme, named in the message as `what`).
int chin_order_index(const Fraction& order, int max_j, const std::string& what);
// How messages and descriptions name those orders: "2/3, 4/3, 2, 8/3, 10/3, 4, ... (2j/3 for j = 1, 2, 3, ...)".
std::string chin_orders_text();

}  // namespace nonsep
