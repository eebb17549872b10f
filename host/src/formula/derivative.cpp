// Partial derivatives of formula trees (derivative.hpp).
#include "nonsep/host/formula/derivative.hpp"

#include <algorithm>
#include <array>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace nonsep::host::formula {

namespace {

using Kind = Node::Kind;
using Terms = std::vector<std::pair<char, Node>>;  // sign ('+' '-' in sums, '*' '/' in products) and operand

constexpr std::array<std::string_view, 8> derivative_rules = {
    "log_derivative", "log1p_derivative", "acosh_derivative", "atanh_derivative",
    "abs_derivative", "min_derivative",   "max_derivative",   "pow_exponent_derivative"};

Node number(double value) { return Node{.kind = Kind::number, .value = value}; }

Node call(std::string function, std::vector<Node> arguments) {
  return Node{.kind = Kind::call, .name = std::move(function), .operands = std::move(arguments)};
}

Node negate(Node x) {
  if (x.kind == Kind::number) return number(-x.value);
  if (x.kind == Kind::negate) return std::move(x.operands[0]);
  return Node{.kind = Kind::negate, .operands = {std::move(x)}};
}

// A node of `kind` (sum or product) from its signed operands.
Node chain_node(Kind kind, Terms terms) {
  Node node{.kind = kind};
  for (auto& [sign, operand] : terms) {
    node.signs.push_back(sign);
    node.operands.push_back(std::move(operand));
  }
  return node;
}

// Moves the first term with sign `first` to the front; false when there is none.
bool lead_with(Terms& terms, char first) {
  for (std::size_t i = 0; i < terms.size(); ++i)
    if (terms[i].first == first) {
      std::rotate(terms.begin(), terms.begin() + static_cast<std::ptrdiff_t>(i),
                  terms.begin() + static_cast<std::ptrdiff_t>(i) + 1);
      return true;
    }
  return false;
}

void add_term(Terms& terms, double& constant, char sign, Node term) {
  if (term.kind == Kind::negate) return add_term(terms, constant, sign == '+' ? '-' : '+', std::move(term.operands[0]));
  if (term.kind == Kind::number) {
    constant += sign == '+' ? term.value : -term.value;
  } else if (term.kind == Kind::sum) {
    for (std::size_t i = 0; i < term.operands.size(); ++i)
      add_term(terms, constant, term.signs[i] == sign ? '+' : '-', std::move(term.operands[i]));
  } else {
    terms.emplace_back(sign, std::move(term));
  }
}

Node sum(Terms given) {
  Terms terms;
  double constant = 0.0;
  for (auto& [sign, term] : given) add_term(terms, constant, sign, std::move(term));
  if (constant != 0.0) terms.emplace_back(constant > 0.0 ? '+' : '-', number(constant > 0.0 ? constant : -constant));
  if (terms.empty()) return number(0.0);
  if (!lead_with(terms, '+')) {
    for (auto& term : terms) term.first = '+';
    return negate(sum(std::move(terms)));
  }
  return terms.size() == 1 ? std::move(terms[0].second) : chain_node(Kind::sum, std::move(terms));
}

void add_factor(Terms& factors, double& coefficient, char sign, Node factor) {
  if (factor.kind == Kind::negate) {
    coefficient = -coefficient;
    return add_factor(factors, coefficient, sign, std::move(factor.operands[0]));
  }
  if (factor.kind == Kind::number) {
    coefficient = sign == '*' ? coefficient * factor.value : coefficient / factor.value;
  } else if (factor.kind == Kind::product) {
    for (std::size_t i = 0; i < factor.operands.size(); ++i)
      add_factor(factors, coefficient, factor.signs[i] == sign ? '*' : '/', std::move(factor.operands[i]));
  } else {
    factors.emplace_back(sign, std::move(factor));
  }
}

Node product(Terms given) {
  Terms factors;
  double coefficient = 1.0;
  for (auto& [sign, factor] : given) add_factor(factors, coefficient, sign, std::move(factor));
  if (coefficient == 0.0 || factors.empty()) return number(coefficient);
  if (coefficient == -1.0) return negate(product(std::move(factors)));
  if (coefficient != 1.0) factors.insert(factors.begin(), {'*', number(coefficient)});
  if (!lead_with(factors, '*')) factors.insert(factors.begin(), {'*', number(1.0)});
  return factors.size() == 1 ? std::move(factors[0].second) : chain_node(Kind::product, std::move(factors));
}

Node power(Node base, Node exponent) {
  if (exponent.kind == Kind::number && exponent.value == 1.0) return base;
  if (exponent.kind == Kind::number && exponent.value == 0.0) return number(1.0);
  return Node{.kind = Kind::power, .operands = {std::move(base), std::move(exponent)}};
}

Node square(const Node& x) { return power(x, number(2.0)); }

Node reciprocal(Node x) { return product({{'*', number(1.0)}, {'/', std::move(x)}}); }

Node times(Node a, Node b) { return product({{'*', std::move(a)}, {'*', std::move(b)}}); }

// d/dx of base^exponent, given the derivatives of both (at least one present).
std::optional<Node> power_derivative(const Node& base, const Node& exponent, const std::optional<Node>& d_base,
                                     const std::optional<Node>& d_exponent) {
  Terms terms;
  if (d_base)
    terms.emplace_back(
        '+',
        product({{'*', exponent}, {'*', power(base, sum({{'+', exponent}, {'-', number(1.0)}}))}, {'*', *d_base}}));
  if (d_exponent)
    terms.emplace_back('+', times(call("pow_exponent_derivative", {base, power(base, exponent)}), *d_exponent));
  return sum(std::move(terms));
}

// f'(u) for the one-argument functions of formula_functions().
Node function_derivative(const std::string& f, const Node& u) {
  const auto call_u = [&](const char* name) { return call(name, {u}); };
  const auto sqrt_of = [&](Node x) { return reciprocal(call("sqrt", {std::move(x)})); };
  if (f == "abs") return call_u("abs_derivative");
  if (f == "acos") return negate(sqrt_of(sum({{'+', number(1.0)}, {'-', square(u)}})));
  if (f == "acosh") return call_u("acosh_derivative");
  if (f == "asin") return sqrt_of(sum({{'+', number(1.0)}, {'-', square(u)}}));
  if (f == "asinh") return sqrt_of(sum({{'+', square(u)}, {'+', number(1.0)}}));
  if (f == "atan") return reciprocal(sum({{'+', number(1.0)}, {'+', square(u)}}));
  if (f == "atanh") return call_u("atanh_derivative");
  if (f == "cbrt") return reciprocal(times(number(3.0), square(call_u("cbrt"))));
  if (f == "cos") return negate(call_u("sin"));
  if (f == "cosh") return call_u("sinh");
  if (f == "cube") return times(number(3.0), square(u));
  if (f == "erf") return times(number(2.0 * std::numbers::inv_sqrtpi), call("exp", {negate(square(u))}));
  if (f == "exp" || f == "expm1") return call_u("exp");
  if (f == "log") return call_u("log_derivative");
  if (f == "log1p") return call_u("log1p_derivative");
  if (f == "sin") return call_u("cos");
  if (f == "sinh") return call_u("cosh");
  if (f == "sqrt") return product({{'*', number(0.5)}, {'/', call_u("sqrt")}});
  if (f == "square") return times(number(2.0), u);
  if (f == "tan") return sum({{'+', number(1.0)}, {'+', square(call_u("tan"))}});
  return sum({{'+', number(1.0)}, {'-', square(call_u("tanh"))}});  // tanh: the last of formula_functions()
}

std::optional<Node> call_derivative(const Node& node, std::size_t index, char letter) {
  const auto& arguments = node.operands;
  if (arguments.size() == 1) {
    auto d = derivative(arguments[0], index, letter);
    if (!d) return std::nullopt;
    return times(function_derivative(node.name, arguments[0]), std::move(*d));
  }
  const Node& a = arguments[0];
  const Node& b = arguments[1];
  const auto da = derivative(a, index, letter);
  const auto db = derivative(b, index, letter);
  if (!da && !db) return std::nullopt;
  if (node.name == "pow") return power_derivative(a, b, da, db);
  if (node.name == "min" || node.name == "max")
    return call(node.name + "_derivative", {a, b, da.value_or(number(0.0)), db.value_or(number(0.0))});
  Terms numerator;
  if (node.name == "atan2") {  // atan2(a, b), the angle of (b, a): (b da - a db) / (a^2 + b^2)
    if (da) numerator.emplace_back('+', times(b, *da));
    if (db) numerator.emplace_back('-', times(a, *db));
    return product({{'*', sum(std::move(numerator))}, {'/', sum({{'+', square(a)}, {'+', square(b)}})}});
  }
  if (da) numerator.emplace_back('+', times(a, *da));  // hypot(a, b): (a da + b db) / hypot(a, b)
  if (db) numerator.emplace_back('+', times(b, *db));
  return product({{'*', sum(std::move(numerator))}, {'/', node}});
}

}  // namespace

std::optional<Node> derivative(const Node& tree, std::size_t index, char letter) {
  switch (tree.kind) {
    case Kind::number:
    case Kind::parameter:
    case Kind::pi:
      return std::nullopt;
    case Kind::variable:
      return tree.index == index && (letter == '\0' || tree.name[0] == letter) ? std::optional<Node>(number(1.0))
                                                                               : std::nullopt;
    case Kind::negate: {
      auto d = derivative(tree.operands[0], index, letter);
      return d ? std::optional<Node>(negate(std::move(*d))) : std::nullopt;
    }
    case Kind::sum: {
      Terms terms;
      for (std::size_t i = 0; i < tree.operands.size(); ++i)
        if (auto d = derivative(tree.operands[i], index, letter)) terms.emplace_back(tree.signs[i], std::move(*d));
      return terms.empty() ? std::nullopt : std::optional<Node>(sum(std::move(terms)));
    }
    case Kind::product: {
      Terms terms;
      for (std::size_t k = 0; k < tree.operands.size(); ++k) {
        auto d = derivative(tree.operands[k], index, letter);
        if (!d) continue;
        Terms factors;
        for (std::size_t j = 0; j < tree.operands.size(); ++j)
          if (j != k) factors.emplace_back(tree.signs[j], tree.operands[j]);
        if (tree.signs[k] == '*') {
          factors.emplace_back('*', std::move(*d));
        } else {  // d(1/f) = -f'/f^2
          factors.emplace_back('*', negate(std::move(*d)));
          factors.emplace_back('/', square(tree.operands[k]));
        }
        terms.emplace_back('+', product(std::move(factors)));
      }
      return terms.empty() ? std::nullopt : std::optional<Node>(sum(std::move(terms)));
    }
    case Kind::power: {
      const auto d_base = derivative(tree.operands[0], index, letter);
      const auto d_exponent = derivative(tree.operands[1], index, letter);
      if (!d_base && !d_exponent) return std::nullopt;
      return power_derivative(tree.operands[0], tree.operands[1], d_base, d_exponent);
    }
    case Kind::call:
      return call_derivative(tree, index, letter);
  }
  return std::nullopt;
}

bool is_derivative_rule(std::string_view function) {
  return std::find(derivative_rules.begin(), derivative_rules.end(), function) != derivative_rules.end();
}

}  // namespace nonsep::host::formula
