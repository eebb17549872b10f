#pragma once
// Formulas of T(p), V(q) and H(q, p): a strict grammar, parsed by recursive descent on a token stream into a tree.
// Nothing of the text survives but the tree: the canonical text (print) and the C++ of a model (cpp_source.hpp) are
// both written from it, so a formula cannot carry anything else to the compiler.
//
//   formula  := sum                                   (at most max_formula_length characters)
//   sum      := product (("+" | "-") product)*
//   product  := unary (("*" | "/") unary)*
//   unary    := ("-" | "+") unary | power
//   power    := primary (("^" | "**") unary)?        right-associative: 2^3^2 = 2^(3^2); -q0^2 = -(q0^2)
//   primary  := number | variable | parameter | "pi" | function "(" sum ("," sum)* ")" | "(" sum ")"
//   number   := digits ["." digits] [("e" | "E") ["+" | "-"] digits], or "." digits [...]: a finite double
//   variable := "q" index (in V and H) or "p" index (in T and H), index 0..max_formula_dimension-1 without leading
//               zeros
// Names are only these: the variables, the parameters the model declares, the constant pi, and the functions of
// formula_functions() (each with its number of arguments). Blanks (space, tab) separate tokens; any other
// character is refused. Nesting (parentheses, signs, powers, calls) is at most max_formula_depth deep, so neither
// the parser nor anything that walks a tree recurses deeper than that; sums and products are n-ary nodes, so a long
// sum makes a wide tree, not a deep one.
//
// Errors: parse_formula returns a FormulaError with the 1-based column of the offending character, what was found
// there and what the grammar allows at that point; describe() writes the formula with a caret under the column.
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace nonsep::host::formula {

inline constexpr std::size_t max_formula_length = 4096;
inline constexpr std::size_t max_formula_depth = 64;
inline constexpr std::size_t max_formula_dimension = 64;

struct Function {
  std::string_view name;
  std::size_t arguments;
};
// The functions a formula may call: the SDK's functions of dual.hpp, for double and dual numbers alike.
std::span<const Function> formula_functions();

struct Node {
  enum class Kind { number, variable, parameter, pi, call, negate, sum, product, power };
  Kind kind = Kind::number;
  double value = 0.0;               // number
  std::string name = {};            // parameter, call (the function); variable: its letter, "q" or "p"
  std::size_t index = 0;            // variable: q<index> or p<index>
  std::vector<Node> operands = {};  // negate: 1; power: base, exponent; call: its arguments; sum, product: 2 or more
  std::vector<char> signs = {};     // sum: '+' or '-' per operand (the first '+'); product: '*' or '/' (the first '*')
  friend bool operator==(const Node&, const Node&) = default;
};

// Which names a formula may use: its variable letters ("q" for V, "p" for T, "qp" for H) and the model's
// parameters.
struct Symbols {
  std::string variables = "q";
  std::vector<std::string> parameters;
};

struct FormulaError {
  std::size_t column = 1;  // 1-based; one past the end for "the formula ends too early"
  std::string found, allowed;
};

std::variant<Node, FormulaError> parse_formula(std::string_view text, const Symbols& symbols);

// The canonical text of a tree: numbers as the shortest text that reads back as the same double, single spaces
// around + and -, parentheses only where the grammar needs them; parse_formula(print(tree)) gives tree again.
std::string print(const Node& tree);

// The largest variable index used plus one (0 when the formula has no variable).
std::size_t dimension_used(const Node& tree);

// "found '*' at column 8 ...": the formula on its own line with a caret under the column, indented by `indent`.
std::string point_at(std::string_view text, std::size_t column, std::string_view indent);

// Whether `name` may name a parameter: [A-Za-z_][A-Za-z0-9_]*, at most 64 characters, and not a variable
// (q<digits>, p<digits>), a function or pi.
bool is_parameter_name(std::string_view name);

}  // namespace nonsep::host::formula
