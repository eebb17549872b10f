// The formula grammar (host/include/nonsep/host/formula/expression.hpp) in-process: well-formed formulas parse and
// print back to the same tree; malformed ones and injection attempts are refused at the right column; nesting
// beyond the limit is refused without deep recursion; the C++ written from a tree holds nothing of the text but
// what the tree says.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "malformed_formulas.hpp"
#include "nonsep/host/formula/cpp_source.hpp"
#include "nonsep/host/formula/derivative.hpp"
#include "nonsep/host/formula/expression.hpp"
#include "nonsep/host/formula/formula_model.hpp"

namespace test_formula_parser {

using namespace nonsep::host::formula;
using nonsep::formula_testing::malformed_formulas;

namespace {

const Symbols q_symbols{"q", {"lambda", "k"}};

FormulaError error_of(const std::string& text, const Symbols& symbols = q_symbols) {
  auto result = parse_formula(text, symbols);
  REQUIRE_MESSAGE(std::holds_alternative<FormulaError>(result), "accepted: " << text);
  return std::get<FormulaError>(result);
}

Node tree_of(const std::string& text, const Symbols& symbols = q_symbols) {
  auto result = parse_formula(text, symbols);
  if (const auto* error = std::get_if<FormulaError>(&result))
    FAIL_CHECK("refused: " << text << ": " << error->found << " at column " << error->column);
  REQUIRE(std::holds_alternative<Node>(result));
  return std::get<Node>(result);
}

}  // namespace

TEST_CASE("formula parser: every malformed formula is refused at its column, saying what is allowed") {
  CHECK(malformed_formulas.size() >= 30);
  for (const auto& malformed : malformed_formulas) {
    const auto& text = malformed.text;  // named, not bound: clang 14 cannot capture a binding
    const auto column = malformed.column;
    const FormulaError error = error_of(text);
    CHECK_MESSAGE(error.column == column, text << ": column " << error.column << ", found " << error.found);
    CHECK_MESSAGE(!error.found.empty(), text);
    CHECK_MESSAGE(!error.allowed.empty(), text);
  }
}

TEST_CASE("formula parser: T refuses q, names the allowed letter, and lists the functions at a bad term") {
  const FormulaError error = error_of("p0 + q0", Symbols{"p", {}});
  CHECK(error.column == 6);
  CHECK(error.allowed.find("p0, p1") != std::string::npos);
  const FormulaError term = error_of("q0 + )");
  CHECK(term.allowed.find("atan2(a, b)") != std::string::npos);
  CHECK(term.allowed.find("lambda") != std::string::npos);
}

TEST_CASE("formula parser: nesting beyond the limit and over-long text are refused, long flat input is fine") {
  std::string deep;
  for (int i = 0; i < 2000; ++i) deep += "(";
  deep += "q0";
  CHECK(error_of(deep).found.find("nesting deeper") != std::string::npos);
  std::string signs(2000, '-');
  CHECK(error_of(signs + "q0").found.find("nesting deeper") != std::string::npos);
  std::string powers = "q0";
  for (int i = 0; i < 200; ++i) powers += "^q0";
  CHECK(error_of(powers).found.find("nesting deeper") != std::string::npos);
  std::string calls;
  for (int i = 0; i < 200; ++i) calls += "sin(";
  CHECK(error_of(calls + "q0").found.find("nesting deeper") != std::string::npos);
  // Exactly max_formula_depth levels of each kind pass, one more is refused (the limit docs/formula-models.md names).
  const auto levels = [](const std::string& open, const std::string& inner, const std::string& close, std::size_t n) {
    std::string text;
    for (std::size_t i = 0; i < n; ++i) text += open;
    text += inner;
    for (std::size_t i = 0; i < n; ++i) text += close;
    return text;
  };
  for (const auto& open_and_close : std::vector<std::pair<std::string, std::string>>{
           {"(", ")"}, {"sin(", ")"}, {"-", ""}, {"q0^", ""}, {"(-", ")"}}) {
    const std::string& open = open_and_close.first;  // not a structured binding: CAPTURE's lambda takes it
    const std::string& close = open_and_close.second;
    CAPTURE(open);
    const std::size_t per = open == "(-" ? 2 : 1;
    CHECK(std::holds_alternative<Node>(parse_formula(levels(open, "q0", close, max_formula_depth / per), q_symbols)));
    CHECK(error_of(levels(open, "q0", close, max_formula_depth / per + 1)).found ==
          "nesting deeper than " + std::to_string(max_formula_depth) + " levels");
  }
  std::string nested = "q0";
  for (int i = 0; i < 20; ++i) nested = "(" + nested + " + 1)";
  CHECK(tree_of(nested).kind == Node::Kind::sum);
  std::string flat = "q0";
  while (flat.size() + 5 < max_formula_length) flat += " + q0";
  const Node wide = tree_of(flat);
  CHECK(wide.operands.size() > 800);
  CHECK(error_of(flat + " + q0 + q0").found.find("characters") != std::string::npos);
  CHECK(error_of(std::string(1 << 20, '1')).column == max_formula_length + 1);
}

TEST_CASE("formula parser: canonical text parses back to the same tree, with the grammar's precedence") {
  const std::vector<std::string> formulas = {
      "q0",
      "q0^2/2 + q0^4/12",
      "-q0^2",
      "(-q0)^2",
      "2^3^2",
      "(2^3)^2",
      "q0 ** 2 * lambda",
      "-(q0 * q1) - -q1",
      "a - (b - c)",  // refused below: unknown names
      "q0 - (q1 - q2) + (q0 + q1)",
      "q0 / (q1 * q2) / q3",
      "atan2(q0, q1) + hypot(q0, 1.5e-3) * pow(q1, k)",
      "exp(-lambda * (q0^2 + q1^2)) + 1e+300 + .5 + 7.",
      "2^-q0 + q0^-2 + q0^(1/3) + pi",
      "+q0 - +1",
  };
  for (const auto& text : formulas) {
    if (text == "a - (b - c)") {
      CHECK(error_of(text).column == 1);
      continue;
    }
    const Node tree = tree_of(text);
    const std::string printed = print(tree);
    CHECK_MESSAGE(tree_of(printed) == tree, text << " -> " << printed);
    CHECK_MESSAGE(print(tree_of(printed)) == printed, printed);
  }
  CHECK(print(tree_of("2^3^2")) == "2^3^2");
  CHECK(tree_of("2^3^2").operands[1].kind == Node::Kind::power);
  CHECK(tree_of("-q0^2").kind == Node::Kind::negate);
  CHECK(print(tree_of("q0*(q1*q2)")) == "q0*(q1*q2)");
  CHECK(print(tree_of("q0 ** 2")) == "q0^2");
  CHECK(dimension_used(tree_of("q0 + q7")) == 8);
}

TEST_CASE("formula C++: written from the tree alone, with products for integer powers") {
  std::vector<nonsep::host::JobIssue> issues;
  const auto model = read_formula_model(nlohmann::json{{"name", "oscillator"},
                                                       {"T", "p0^2 / 2"},
                                                       {"V", "q0^2/4   + lambda*q0^4/24"},
                                                       {"U", "alpha^2 * q0^2 / (2 * (1 + lambda * q0^2))"},
                                                       {"parameters", {{"lambda", 0.5}, {"alpha", 1}}}},
                                        "/model/formula", ".", issues);
  REQUIRE(issues.empty());
  REQUIRE(model);
  CHECK(model->V == "q0^2/4 + lambda*q0^4/24");
  const std::string source = cpp_source(*model);
  CHECK(source.find("integer_power<4>(q[0])") != std::string::npos);
  CHECK(source.find("parameter_lambda") != std::string::npos);
  CHECK(source.find("S U(") != std::string::npos);
  CHECK(source.find("S K(") == std::string::npos);
  CHECK(source.find("q0^2/4   +") == std::string::npos);
}

TEST_CASE("formula C++: bounded by the formula, whatever its products (repeated factors, an outgrown gradient)") {
  const auto source_of = [](const std::string& V) {
    std::vector<nonsep::host::JobIssue> issues;
    const auto model =
        read_formula_model(nlohmann::json{{"name", "product"}, {"T", "p0^2/2"}, {"V", V}}, "/f", ".", issues);
    REQUIRE(model);
    return cpp_source(*model);
  };
  // 1365 factors q0 (4094 characters): once as a power, in the value and in the gradient (13 MB of C++ before).
  std::string repeated = "q0";
  while (repeated.size() + 3 <= max_formula_length) repeated += "*q0";
  const std::string power = source_of(repeated);
  CHECK(power.size() < 20000);
  CHECK(power.find("::nonsep::sdk::pow(S(q[0]), 1365.0)") != std::string::npos);
  // 467 distinct factors: the written gradient would have 467 * 466 of them; the SDK differentiates V instead.
  std::string distinct = "(q0 + 1)";
  for (int k = 2; distinct.size() + 11 <= max_formula_length; ++k) distinct += "*(q0 + " + std::to_string(k) + ")";
  const std::string automatic = source_of(distinct);
  CHECK(automatic.find("grad_V") == std::string::npos);
  CHECK(automatic.find("grad_T") != std::string::npos);
  CHECK(automatic.size() < 6 * distinct.size() + 5000);  // its parts' headers included
  // A small formula keeps its written gradient.
  CHECK(source_of("q0^2/2 + q0^4/12").find("grad_V") != std::string::npos);
}

TEST_CASE("formula C++: long sums and products are cut into parts of bounded size that are not inlined") {
  const auto source_of = [](const std::string& V) {
    std::vector<nonsep::host::JobIssue> issues;
    const auto model =
        read_formula_model(nlohmann::json{{"name", "long"}, {"T", "p0^2/2"}, {"V", V}}, "/f", ".", issues);
    REQUIRE(model);
    return cpp_source(*model);
  };
  // The longest statement of the functions (a return or a gradient component), in characters: what the compiler
  // optimises as one function grows with it.
  const auto longest_statement = [](const std::string& source) {
    std::size_t longest = 0, start = 0;
    for (std::size_t end; (end = source.find('\n', start)) != std::string::npos; start = end + 1)
      if (source.compare(start, 11, "    return ") == 0 || source.compare(start, 8, "    out[") == 0)
        longest = std::max(longest, end - start);
    return longest;
  };
  std::string product = "(q0 + 1)";  // 467 distinct factors (4094 characters)
  for (int k = 2; product.size() + 11 <= max_formula_length; ++k) product += "*(q0 + " + std::to_string(k) + ")";
  std::string sines = "sin(q0 + 1)";  // 280 distinct terms
  for (int k = 2;; ++k) {
    const std::string term = " + sin(q0 + " + std::to_string(k) + ")";
    if (sines.size() + term.size() > max_formula_length) break;
    sines += term;
  }
  std::string nested = "q0";  // sums inside sums: (1 + q0*(2 + q0*(3 + ...)))
  for (int k = 1; nested.size() + 16 <= max_formula_length - 64 && k < 60; ++k)
    nested = "(" + std::to_string(k) + " + q0*q1*" + nested + ")";
  for (const std::string& formula : {product, sines, nested, std::string("q0^2/2 + q0^4/12")}) {
    const std::string source = source_of(formula);
    const std::size_t longest = longest_statement(source);
    CAPTURE(formula.size());
    CAPTURE(longest);
    CHECK(longest < 2500);
    const bool long_formula = formula.size() > 200;
    CHECK((source.find("[[gnu::noinline]] S part_0(") != std::string::npos) == long_formula);
  }
  // Runs of terms with their signs become parts, joined in the formula's order.
  std::string alternating = "q0";
  for (int k = 1; alternating.size() + 24 <= 1000; ++k)
    alternating += (k % 2 ? " - " : " + ") + std::string("q0*(q0 + ") + std::to_string(k) + ")/" + std::to_string(k);
  const std::string source = source_of(alternating);
  CHECK(source.find("part_0<S>(q) + part_1<S>(q)") != std::string::npos);
}

TEST_CASE("formula models: bad keys, parameter names, names and dimensions are issues at their pointers") {
  std::vector<nonsep::host::JobIssue> issues;
  CHECK(!read_formula_model(nlohmann::json{{"T", "p0"},
                                           {"V", "q0 +"},
                                           {"W", "1"},
                                           {"name", "Bad-Name\"; int x;"},
                                           {"dimension", 0},
                                           {"parameters", {{"q1", 1}, {"sin", 2}, {"a;b", 3}, {"ok", "x"}}}},
                            "/model/formula", ".", issues));
  std::vector<std::string> paths;
  for (const auto& issue : issues) paths.push_back(issue.path);
  for (const std::string expected :
       {"/model/formula/W", "/model/formula/name", "/model/formula/V", "/model/formula/parameters/q1",
        "/model/formula/parameters/sin", "/model/formula/parameters/a;b", "/model/formula/parameters/ok"})
    CHECK_MESSAGE(std::find(paths.begin(), paths.end(), expected) != paths.end(), expected);
  issues.clear();
  CHECK(!read_formula_model(nlohmann::json{{"T", "p0 + p3"}, {"V", "q0"}, {"dimension", 2}}, "/f", ".", issues));
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/f/dimension");
}

TEST_CASE("formula parser: H takes q and p, prints each variable with its letter, differentiates by each") {
  const Symbols both{"qp", {"e"}};
  const Node tree = tree_of("(p0 - e*q1)^2/2 + p1^2/2 + q0^2*p1", both);
  CHECK(print(tree) == "(p0 - e*q1)^2/2 + p1^2/2 + q0^2*p1");
  CHECK(tree_of(print(tree), both) == tree);
  CHECK(dimension_used(tree) == 2);
  CHECK(dimension_used(tree_of("p4 + q1", both)) == 5);
  // d/dq1 and d/dp1 are different derivatives of the same index.
  CHECK(print(*derivative(tree, 1, 'q')) == "-((p0 - e*q1)*e)");
  CHECK(print(*derivative(tree, 1, 'p')) == "p1 + q0^2");
  CHECK(print(*derivative(tree, 0, 'q')) == "2*p1*q0");
  CHECK_FALSE(derivative(tree_of("p0^2 + q1", both), 0, 'q').has_value());
  const FormulaError unknown = error_of("q0 + x1", both);
  CHECK(unknown.column == 6);
  CHECK(unknown.allowed.find("q0, q1, ..., p0, p1, ...") != std::string::npos);
}

TEST_CASE("formula models: H alone or T and V, never both, its dimension counting q and p, its C++ a Hamiltonian") {
  std::vector<nonsep::host::JobIssue> issues;
  CHECK(!read_formula_model(nlohmann::json{{"H", "p0^2/2 + q0^2/2"}, {"T", "p0^2/2"}, {"U", "q0"}}, "/f", ".", issues));
  std::vector<std::string> paths;
  for (const auto& issue : issues) paths.push_back(issue.path);
  CHECK(paths == std::vector<std::string>{"/f/T", "/f/U"});
  REQUIRE(!issues.empty());
  CHECK(issues[0].found == "both H and T");
  issues.clear();
  CHECK(!read_formula_model(nlohmann::json{{"H", nlohmann::json::array({"p0^2"})}}, "/f", ".", issues));
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/f/H");
  CHECK(issues[0].allowed.find("q0, q1, ..., p0, p1, ...") != std::string::npos);
  issues.clear();
  CHECK(!read_formula_model(nlohmann::json{{"H", "p0^2/2 + r0"}}, "/f", ".", issues));
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].found.find("the unknown name r0") != std::string::npos);
  issues.clear();
  const auto model = read_formula_model(
      nlohmann::json{{"name", "gauge"}, {"H", "(p0 - b*q1)^2/2 + p2^2/2"}, {"parameters", {{"b", 0.5}}}}, "/f", ".",
      issues);
  REQUIRE(issues.empty());
  REQUIRE(model);
  CHECK(model->dimension == 3);
  CHECK(model->H == "(p0 - b*q1)^2/2 + p2^2/2");
  CHECK(formula_record(*model, "k")["H"] == model->H);
  CHECK(formula_record(*model, "k")["T"].is_null());
  const std::string source = cpp_source(*model);
  CHECK(source.find("NONSEP_EXPORT_HAMILTONIAN(Formula, \"gauge\"") != std::string::npos);
  CHECK(source.find("S H([[maybe_unused]] nonsep::sdk::Vector<S> q, [[maybe_unused]] nonsep::sdk::Vector<S> p)") !=
        std::string::npos);
  CHECK(source.find("void grad_H(") != std::string::npos);
  CHECK(source.find("dH_dq[1] = S(") != std::string::npos);
  CHECK(source.find("dH_dp[2] = S(p[2])") != std::string::npos);
  CHECK(source.find("S T(") == std::string::npos);
}

}  // namespace test_formula_parser
