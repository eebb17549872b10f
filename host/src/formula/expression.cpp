// The formula grammar of expression.hpp: a tokenizer and a recursive-descent parser (the canonical printer is
// expression_printer.cpp).
#include "nonsep/host/formula/expression.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace nonsep::host::formula {

namespace {

constexpr Function functions[] = {{"abs", 1},    {"acos", 1},  {"acosh", 1}, {"asin", 1},  {"asinh", 1}, {"atan", 1},
                                  {"atan2", 2},  {"atanh", 1}, {"cbrt", 1},  {"cos", 1},   {"cosh", 1},  {"cube", 1},
                                  {"erf", 1},    {"exp", 1},   {"expm1", 1}, {"hypot", 2}, {"log", 1},   {"log1p", 1},
                                  {"max", 2},    {"min", 2},   {"pow", 2},   {"sin", 1},   {"sinh", 1},  {"sqrt", 1},
                                  {"square", 1}, {"tan", 1},   {"tanh", 1}};

const Function* find_function(std::string_view name) {
  for (const auto& function : functions)
    if (function.name == name) return &function;
  return nullptr;
}

// "q12" -> 12 for letter 'q'; nothing for anything else (leading zeros included).
std::optional<std::size_t> variable_index(std::string_view name, char letter) {
  if (name.size() < 2 || name[0] != letter) return std::nullopt;
  const std::string_view digits = name.substr(1);
  if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) return std::nullopt;
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;
  if (digits.size() > 6) return std::size_t{1'000'000};
  std::size_t index = 0;
  std::from_chars(digits.data(), digits.data() + digits.size(), index);
  return index;
}

bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

struct Token {
  enum class Kind { number, name, symbol, end } kind = Kind::end;
  std::string_view text;
  std::size_t column = 1;
  double value = 0.0;
};

// Describes a character for a message: 'x', or its code for control and non-ASCII bytes.
std::string show_character(char c) {
  const auto byte = static_cast<unsigned char>(c);
  if (byte >= 0x21 && byte < 0x7f) return std::string("'") + c + "'";
  char code[32];
  std::snprintf(code, sizeof code, "the byte 0x%02X", byte);
  return code;
}

class Parser {
 public:
  Parser(std::string_view text, const Symbols& symbols) : text_(text), symbols_(symbols) {}

  std::variant<Node, FormulaError> run() {
    if (text_.size() > max_formula_length)
      return FormulaError{max_formula_length + 1, "a formula of " + std::to_string(text_.size()) + " characters",
                          "at most " + std::to_string(max_formula_length) + " characters"};
    if (!tokenize()) return *error_;
    if (tokens_.front().kind == Token::Kind::end)
      return FormulaError{tokens_.front().column, "an empty formula", term_text()};
    Node tree = sum();
    if (error_) return *error_;
    if (peek().kind != Token::Kind::end)
      return FormulaError{peek().column, describe(peek()) + " after a complete formula",
                          "an operator (+ - * / ^) or the end of the formula"};
    return tree;
  }

 private:
  std::string term_text() const {
    std::string names = "a number, the variables ";
    for (const char letter : symbols_.variables)
      names += std::string(letter == symbols_.variables.front() ? "" : ", ") + letter + "0, " + letter + "1, ...";
    for (const auto& parameter : symbols_.parameters) names += ", the parameter " + parameter;
    names += ", pi, a function (";
    for (std::size_t i = 0; i < std::size(functions); ++i)
      names += (i == 0 ? "" : ", ") + std::string(functions[i].name) + (functions[i].arguments == 2 ? "(a, b)" : "");
    return names + "), '(' or a sign";
  }

  static std::string describe(const Token& token) {
    if (token.kind == Token::Kind::end) return "the end of the formula";
    return "'" + std::string(token.text) + "'";
  }

  void fail(std::size_t column, std::string found, std::string allowed) {
    if (!error_) error_ = FormulaError{column, std::move(found), std::move(allowed)};
  }

  bool tokenize() {
    std::size_t i = 0;
    while (i < text_.size()) {
      const char c = text_[i];
      const std::size_t column = i + 1;
      if (c == ' ' || c == '\t') {
        ++i;
      } else if (is_digit(c) || (c == '.' && i + 1 < text_.size() && is_digit(text_[i + 1]))) {
        std::size_t end = i;
        while (end < text_.size() && is_digit(text_[end])) ++end;
        if (end < text_.size() && text_[end] == '.') ++end;
        while (end < text_.size() && is_digit(text_[end])) ++end;
        if (end < text_.size() && (text_[end] == 'e' || text_[end] == 'E')) {
          std::size_t exponent = end + 1;
          if (exponent < text_.size() && (text_[exponent] == '+' || text_[exponent] == '-')) ++exponent;
          if (exponent >= text_.size() || !is_digit(text_[exponent])) {
            fail(exponent + 1, "a number whose exponent has no digits", "digits after e, as in 1.5e-3");
            return false;
          }
          end = exponent;
          while (end < text_.size() && is_digit(text_[end])) ++end;
        }
        if (end < text_.size() && is_name_char(text_[end])) {
          fail(end + 1, show_character(text_[end]) + " right after the number " + std::string(text_.substr(i, end - i)),
               "an operator between a number and a name (2*q0, not 2q0)");
          return false;
        }
        Token token{Token::Kind::number, text_.substr(i, end - i), column};
        const auto result = std::from_chars(token.text.data(), token.text.data() + token.text.size(), token.value);
        if (result.ec != std::errc() || result.ptr != token.text.data() + token.text.size() ||
            !std::isfinite(token.value)) {
          fail(column, "the number " + std::string(token.text) + ", which a double cannot hold",
               "numbers from about 2.2e-308 to 1.8e308 in magnitude, or 0");
          return false;
        }
        tokens_.push_back(token);
        i = end;
      } else if (is_name_start(c)) {
        std::size_t end = i;
        while (end < text_.size() && is_name_char(text_[end])) ++end;
        tokens_.push_back({Token::Kind::name, text_.substr(i, end - i), column});
        i = end;
      } else if (c == '*' && i + 1 < text_.size() && text_[i + 1] == '*') {
        tokens_.push_back({Token::Kind::symbol, text_.substr(i, 2), column});
        i += 2;
      } else if (std::string_view("+-*/^(),").find(c) != std::string_view::npos) {
        tokens_.push_back({Token::Kind::symbol, text_.substr(i, 1), column});
        ++i;
      } else {
        fail(column, show_character(c),
             "numbers, names, the operators + - * / ^ (or **), parentheses, commas between a function's arguments, "
             "blanks");
        return false;
      }
    }
    tokens_.push_back({Token::Kind::end, {}, text_.size() + 1});
    return true;
  }

  const Token& peek() const { return tokens_[position_]; }
  bool at_symbol(std::string_view symbol) const { return peek().kind == Token::Kind::symbol && peek().text == symbol; }

  // Counts nesting for the depth limit; false (with the error) beyond it.
  bool enter() {
    if (++depth_ <= max_formula_depth) return true;
    fail(peek().column, "nesting deeper than " + std::to_string(max_formula_depth) + " levels",
         "at most " + std::to_string(max_formula_depth) + " nested parentheses, signs, powers and calls");
    return false;
  }

  // One left-associative level of n-ary operators (sums: + -, products: * /): an operand of the next level, then
  // any number of (operator, operand); a lone operand is returned as it is.
  Node chain(Node::Kind kind, const char* first, const char* second, Node (Parser::*operand)()) {
    Node head = (this->*operand)();
    if (error_ || !(at_symbol(first) || at_symbol(second))) return head;
    Node node{.kind = kind};
    node.operands.push_back(std::move(head));
    node.signs.push_back(first[0]);
    while (!error_ && (at_symbol(first) || at_symbol(second))) {
      node.signs.push_back(peek().text[0]);
      ++position_;
      node.operands.push_back((this->*operand)());
    }
    return node;
  }

  Node sum() { return chain(Node::Kind::sum, "+", "-", &Parser::product); }
  Node product() { return chain(Node::Kind::product, "*", "/", &Parser::unary); }

  // Every recursion passes through one enter(): a sign, a power's exponent, a parenthesis, a call's arguments; so
  // each of them is one level, and nothing else is.
  Node unary() {
    if (!(at_symbol("-") || at_symbol("+"))) return power();
    if (!enter()) return {};
    const bool negative = at_symbol("-");
    ++position_;
    Node result;
    Node operand = unary();
    if (negative) {
      result.kind = Node::Kind::negate;
      result.operands.push_back(std::move(operand));
    } else {
      result = std::move(operand);
    }
    --depth_;
    return result;
  }

  Node power() {
    Node base = primary();
    if (error_ || !(at_symbol("^") || at_symbol("**"))) return base;
    ++position_;
    if (!enter()) return {};
    Node node{.kind = Node::Kind::power};
    node.operands.push_back(std::move(base));
    node.operands.push_back(unary());
    --depth_;
    return node;
  }

  Node primary() {
    const Token token = peek();
    if (token.kind == Token::Kind::number) {
      ++position_;
      return Node{.kind = Node::Kind::number, .value = token.value};
    }
    if (at_symbol("(")) {
      ++position_;
      if (!enter()) return {};
      Node inner = sum();
      --depth_;
      if (!error_ && !at_symbol(")"))
        fail(peek().column,
             describe(peek()) + " where the parenthesis opened at column " + std::to_string(token.column) +
                 " must close",
             "an operator or ')'");
      ++position_;
      return inner;
    }
    if (token.kind != Token::Kind::name) {
      fail(token.column, describe(token) + " where a term must begin", term_text());
      return {};
    }
    ++position_;
    const std::string name(token.text);
    if (const Function* function = find_function(name)) return call(*function, token);
    if (at_symbol("(")) {
      fail(token.column, "the unknown function " + name, term_text());
      return {};
    }
    if (name == "pi") return Node{.kind = Node::Kind::pi};
    for (const char letter : symbols_.variables)
      if (const auto index = variable_index(name, letter)) {
        if (*index >= max_formula_dimension)
          fail(token.column, "the variable " + name,
               "indices 0.." + std::to_string(max_formula_dimension - 1) + " (at most " +
                   std::to_string(max_formula_dimension) + " dimensions)");
        return Node{.kind = Node::Kind::variable, .name = std::string(1, letter), .index = *index};
      }
    if (std::find(symbols_.parameters.begin(), symbols_.parameters.end(), name) != symbols_.parameters.end())
      return Node{.kind = Node::Kind::parameter, .name = name};
    const bool in_v = symbols_.variables == "q";
    if (symbols_.variables.size() == 1 && variable_index(name, in_v ? 'p' : 'q'))
      fail(token.column, "the variable " + name + " in " + (in_v ? "V(q)" : "T(p)"),
           "only " + symbols_.variables + "0, " + symbols_.variables +
               "1, ... here: " + (in_v ? "V depends on q alone" : "T depends on p alone"));
    else
      fail(token.column, "the unknown name " + name, term_text());
    return {};
  }

  Node call(const Function& function, const Token& token) {
    if (!at_symbol("(")) {
      fail(peek().column, describe(peek()) + " after the function " + std::string(function.name),
           "'(' and its argument" + std::string(function.arguments == 2 ? "s" : ""));
      return {};
    }
    const std::size_t open = peek().column;
    ++position_;
    if (!enter()) return {};
    Node node{.kind = Node::Kind::call, .name = std::string(function.name)};
    while (!error_) {
      node.operands.push_back(sum());
      if (error_ || !at_symbol(",")) break;
      ++position_;
    }
    --depth_;
    if (error_) return {};
    if (!at_symbol(")")) {
      fail(peek().column,
           describe(peek()) + " in the call of " + std::string(function.name) + " opened at column " +
               std::to_string(open),
           "',' between arguments or ')'");
      return {};
    }
    if (node.operands.size() != function.arguments) {
      fail(token.column,
           std::string(function.name) + " with " + std::to_string(node.operands.size()) + " argument" +
               (node.operands.size() == 1 ? "" : "s"),
           std::string(function.name) + " with " + std::to_string(function.arguments) + " argument" +
               (function.arguments == 1 ? "" : "s"));
      return {};
    }
    ++position_;
    return node;
  }

  std::string_view text_;
  const Symbols& symbols_;
  std::vector<Token> tokens_;
  std::size_t position_ = 0, depth_ = 0;
  std::optional<FormulaError> error_;
};

}  // namespace

std::span<const Function> formula_functions() { return functions; }

std::variant<Node, FormulaError> parse_formula(std::string_view text, const Symbols& symbols) {
  return Parser(text, symbols).run();
}

std::size_t dimension_used(const Node& tree) {
  std::size_t dimension = tree.kind == Node::Kind::variable ? tree.index + 1 : 0;
  for (const Node& operand : tree.operands) dimension = std::max(dimension, dimension_used(operand));
  return dimension;
}

std::string point_at(std::string_view text, std::size_t column, std::string_view indent) {
  std::string shown;
  for (const char c : text) shown += (c == '\t' || static_cast<unsigned char>(c) < 0x20) ? ' ' : c;
  if (shown.size() > 160) {
    const std::size_t start = column > 80 ? column - 80 : 0;
    shown = (start > 0 ? "..." : "") + shown.substr(start, 160) + (start + 160 < shown.size() ? "..." : "");
    column = column - start + (start > 0 ? 3 : 0);
  }
  return std::string(indent) + shown + "\n" + std::string(indent) + std::string(column - 1, ' ') + "^";
}

bool is_parameter_name(std::string_view name) {
  if (name.empty() || name.size() > 64 || !is_name_start(name[0])) return false;
  if (!std::all_of(name.begin(), name.end(), is_name_char)) return false;
  return !variable_index(name, 'q') && !variable_index(name, 'p') && !find_function(name) && name != "pi";
}

}  // namespace nonsep::host::formula
