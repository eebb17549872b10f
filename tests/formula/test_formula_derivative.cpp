// The derivatives of formula trees (host/include/nonsep/host/formula/derivative.hpp) against automatic
// differentiation of the same trees with the SDK's dual numbers: the tree is evaluated by an interpreter written
// here (the oracle), once on duals seeded along x_i and once, as a derivative tree, on doubles. Every function of
// the grammar appears, with the special cases the SDK gives rules of their own.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <nonsep/sdk/dual.hpp>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "nonsep/host/formula/derivative.hpp"
#include "nonsep/host/formula/expression.hpp"

namespace test_formula_derivative {

using namespace nonsep::host::formula;
namespace sdk = nonsep::sdk;

namespace {

using Dual = sdk::Dual<double, 1>;
const std::map<std::string, double> parameter_values{{"lambda", 0.7}, {"k", -1.3}};

template <class S>
S function_value(const std::string& f, const std::vector<S>& a) {
  using namespace nonsep::sdk;
  if (f == "abs") return abs(a[0]);
  if (f == "acos") return acos(a[0]);
  if (f == "acosh") return acosh(a[0]);
  if (f == "asin") return asin(a[0]);
  if (f == "asinh") return asinh(a[0]);
  if (f == "atan") return atan(a[0]);
  if (f == "atan2") return atan2(a[0], a[1]);
  if (f == "atanh") return atanh(a[0]);
  if (f == "cbrt") return cbrt(a[0]);
  if (f == "cos") return cos(a[0]);
  if (f == "cosh") return cosh(a[0]);
  if (f == "cube") return cube(a[0]);
  if (f == "erf") return erf(a[0]);
  if (f == "exp") return exp(a[0]);
  if (f == "expm1") return expm1(a[0]);
  if (f == "hypot") return hypot(a[0], a[1]);
  if (f == "log") return log(a[0]);
  if (f == "log1p") return log1p(a[0]);
  if (f == "max") return max(a[0], a[1]);
  if (f == "min") return min(a[0], a[1]);
  if (f == "pow") return pow(a[0], a[1]);
  if (f == "sin") return sin(a[0]);
  if (f == "sinh") return sinh(a[0]);
  if (f == "sqrt") return sqrt(a[0]);
  if (f == "square") return square(a[0]);
  if (f == "tan") return tan(a[0]);
  if (f == "tanh") return tanh(a[0]);
  if (f == "log_derivative") return log_derivative(a[0]);
  if (f == "log1p_derivative") return log1p_derivative(a[0]);
  if (f == "acosh_derivative") return acosh_derivative(a[0]);
  if (f == "atanh_derivative") return atanh_derivative(a[0]);
  if (f == "abs_derivative") return abs_derivative(a[0]);
  if (f == "pow_exponent_derivative") return pow_exponent_derivative(a[0], a[1]);
  if (f == "min_derivative") return min_derivative(a[0], a[1], a[2], a[3]);
  if (f == "max_derivative") return max_derivative(a[0], a[1], a[2], a[3]);
  FAIL("no such function in the oracle: " << f);
  return S(0.0);
}

template <class S>
S evaluate(const Node& node, std::span<const S> x) {
  switch (node.kind) {
    case Node::Kind::number:
      return S(node.value);
    case Node::Kind::variable:
      return x[node.index];
    case Node::Kind::parameter:
      return S(parameter_values.at(node.name));
    case Node::Kind::pi:
      return S(std::numbers::pi);
    case Node::Kind::negate:
      return -evaluate(node.operands[0], x);
    case Node::Kind::power:
      return sdk::pow(evaluate(node.operands[0], x), evaluate(node.operands[1], x));
    case Node::Kind::call: {
      std::vector<S> arguments;
      for (const Node& operand : node.operands) arguments.push_back(evaluate(operand, x));
      return function_value(node.name, arguments);
    }
    case Node::Kind::sum:
    case Node::Kind::product: {
      S result = evaluate(node.operands[0], x);
      for (std::size_t i = 1; i < node.operands.size(); ++i) {
        const S operand = evaluate(node.operands[i], x);
        if (node.signs[i] == '+') result += operand;
        if (node.signs[i] == '-') result -= operand;
        if (node.signs[i] == '*') result *= operand;
        if (node.signs[i] == '/') result /= operand;
      }
      return result;
    }
  }
  return S(0.0);
}

Node tree_of(const std::string& text) {
  auto result = parse_formula(text, Symbols{"q", {"lambda", "k"}});
  REQUIRE_MESSAGE(std::holds_alternative<Node>(result), "refused: " << text);
  return std::get<Node>(result);
}

// d tree / d x_i at x by automatic differentiation of the tree.
double automatic(const Node& tree, std::vector<double> x, std::size_t i) {
  std::vector<Dual> duals(x.begin(), x.end());
  duals[i].derivative[0] = 1.0;
  return evaluate<Dual>(tree, duals).derivative[0];
}

// d tree / d x_i at x from the derivative tree (0 where derivative() says the tree does not depend on x_i).
double symbolic(const Node& tree, const std::vector<double>& x, std::size_t i) {
  const auto d = derivative(tree, i);
  return d ? evaluate<double>(*d, x) : 0.0;
}

bool same(double a, double b) {
  if (!std::isfinite(a) || !std::isfinite(b)) return a == b || (std::isnan(a) && std::isnan(b));
  return std::abs(a - b) <= 1e-12 * std::max(1.0, std::abs(a));
}

// The gradient at x both ways agrees: component by component where automatic differentiation gives a finite
// number (or the tree a non-finite one), and in being non-finite somewhere. Where AD multiplies an infinite or NaN
// derivative (abs at 0, sqrt at 0) by another variable's zero derivative it writes NaN in that component too; the
// tree writes the component's own value there. The state is non-finite either way, so a run diverges alike.
void check_gradient(const std::string& text, const std::vector<double>& x) {
  const Node tree = tree_of(text);
  bool automatic_finite = true, symbolic_finite = true;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double expected = automatic(tree, x, i);
    const double found = symbolic(tree, x, i);
    automatic_finite = automatic_finite && std::isfinite(expected);
    symbolic_finite = symbolic_finite && std::isfinite(found);
    INFO(text << " d/dq" << i << " at (" << x[0] << ", " << x[1] << (x.size() > 2 ? ", " + std::to_string(x[2]) : "")
              << "): automatic " << expected << ", from the tree " << found);
    if (std::isfinite(expected) || !std::isfinite(found)) CHECK(same(expected, found));
  }
  INFO(text << ": automatic gradient finite " << automatic_finite << ", from the tree " << symbolic_finite);
  CHECK(automatic_finite == symbolic_finite);
}

}  // namespace

TEST_CASE("formula derivatives: every function and operator agrees with automatic differentiation") {
  const std::vector<std::string> formulas = {
      "q0^2/2 + q0^4/12",
      "sin(q0)*cos(q1) - tan(q0*q1) + sinh(q1)/cosh(q0) + tanh(q0 - q1)",
      "exp(q0*q1) + expm1(q0) + log(q0 + q1) + log1p(q1) - 3*q2",
      "sqrt(q0^2 + q1^2) + cbrt(q0 + 2) + hypot(q0, q1) + atan2(q1, q0) + atan2(q0^2, 2) + hypot(3, q1)",
      "asin(q0/2) + acos(q1/2) + atan(q0*q1) + asinh(q0) + acosh(1 + q1^2) + atanh(q0/2)",
      "erf(q0*q1) + square(q0 - q1) + cube(q1) + abs(q0 - 0.1) * q2",
      "pow(q0, 2.5) + q1^q0 + 2^q1 + q0^-3 + q0^(1/3) + pow(q1, q0) + q0^lambda + pow(q1, -2)",
      "min(q0, q1^2) + max(q0*q1, 0.3) + min(q0, 2) * max(q1, 0) + max(1, q2)",
      "lambda * q0 / (1 + q1^2) / (q0 - 3) - -q1 * (q0 / q1) + k / q2 / q2",
      "(q0 + q1 + q2)^3 - q2 + -(q0*q1*q2)^2 + 1/(q0*q1)",
      "sin(cos(sin(q0 * q1)))^2 * exp(-(q0^2 + q1^2)/2) / (2*pi)",
      "q0^0 + q1^1 + 0*q2 + q0*0 + (q1 - q1)",
  };
  const std::vector<std::vector<double>> points = {{0.3, 0.6, 0.9}, {0.71, 0.45, -0.2}, {0.1, 0.95, 1.7}};
  for (const auto& text : formulas)
    for (const auto& x : points) check_gradient(text, x);
}

TEST_CASE("formula derivatives: the special cases are the SDK's (domains, ties, kinks)") {
  const std::vector<std::pair<std::string, std::vector<double>>> cases = {
      {"log(q0)", {-0.5, 0.0}},      // NaN below 0, not -1/0.5
      {"log1p(q0)", {-1.5, 0.0}},    // NaN below -1
      {"abs(q0)", {0.0, 0.0}},       // NaN at the kink
      {"abs(q0)", {-2.0, 0.0}},      // -1
      {"min(q0, q1)", {0.4, 0.4}},   // a tie: the first argument's derivative
      {"max(q1, q0)", {0.4, 0.4}},   //
      {"max(q0, q1)", {0.2, 0.4}},   //
      {"pow(q0, q1)", {-2.0, 3.0}},  // no derivative in the exponent at a base <= 0
      {"q0^q1", {0.0, 2.0}},         //
      {"sqrt(q0)", {0.0, 1.0}},      // inf
      {"acosh(q0) + atanh(q1)", {-3.0, 2.0}},
  };
  for (const auto& [text, x] : cases) check_gradient(text, x);
}

TEST_CASE("formula derivatives: zero where a tree does not depend on the variable, folded where it does") {
  CHECK_FALSE(derivative(tree_of("q0^2 + sin(q2)"), 1).has_value());
  CHECK_FALSE(derivative(tree_of("sin(2) * 3 + lambda^k"), 0).has_value());
  const auto d = derivative(tree_of("q0^2/2 + q0^4/12"), 0);
  REQUIRE(d.has_value());
  CHECK(print(*d) == "q0 + 0.3333333333333333*q0^3");
  const auto constant = derivative(tree_of("3*q0 - q0/2"), 0);
  REQUIRE(constant.has_value());
  CHECK(print(*constant) == "2.5");
}

TEST_CASE("formula derivatives: the SDK's derivative rules are names a formula cannot use") {
  for (const char* rule : {"log_derivative", "log1p_derivative", "acosh_derivative", "atanh_derivative",
                           "abs_derivative", "min_derivative", "max_derivative", "pow_exponent_derivative"}) {
    CHECK(is_derivative_rule(rule));
    const auto result = parse_formula(std::string(rule) + "(q0)", Symbols{"q", {}});
    CHECK_MESSAGE(std::holds_alternative<FormulaError>(result), rule);
  }
  CHECK_FALSE(is_derivative_rule("log"));
}

}  // namespace test_formula_derivative
