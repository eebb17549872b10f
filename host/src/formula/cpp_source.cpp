// The C++ of a formula model (cpp_source.hpp), written from its trees.
#include "nonsep/host/formula/cpp_source.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>

#include "nonsep/host/formula/derivative.hpp"

namespace nonsep::host::formula {

namespace {

// A double literal that reads back as `value` (finite: the parser refuses anything else).
std::string literal(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  std::string text(buffer, result.ptr);
  if (text.find_first_of(".e") == std::string::npos) text += ".0";
  return text;
}

// The exponent n of x^n when it is an integer literal with |n| <= 64.
std::optional<int> small_integer(const Node& exponent) {
  const Node* number = &exponent;
  int sign = 1;
  if (exponent.kind == Node::Kind::negate) {
    number = &exponent.operands[0];
    sign = -1;
  }
  if (number->kind != Node::Kind::number || std::abs(number->value) > 64 || number->value != std::floor(number->value))
    return std::nullopt;
  return sign * static_cast<int>(number->value);
}

std::size_t node_count(const Node& tree) {
  std::size_t count = 1;
  for (const auto& operand : tree.operands) count += node_count(operand);
  return count;
}

// The C++ of trees over the variables of `letters` ("q", "p", or "qp" for H). A sum or product of more than
// max_part_nodes nodes is cut into parts of consecutive operands of at most that many nodes together, each part a
// member function of its own that the compiler does not inline ([[gnu::noinline]]): the optimiser's work grows faster
// than the function it works on (with the nested dual numbers of the third derivatives, a product of 50 distinct
// factors took twice the CPU time of one of 25), so a formula is compiled as functions of bounded size, and its compile
// time grows with its length. The parts' definitions collect in `parts`, numbered across the whole class by `count`.
class ExpressionWriter {
 public:
  ExpressionWriter(std::string letters, std::string& parts, std::size_t& count)
      : letters_(std::move(letters)), parts_(parts), count_(count) {}

  // The function parameters of the variables: "[[maybe_unused]] nonsep::sdk::Vector<S> q" (and p), of type `type`.
  std::string parameters(const std::string& type = "nonsep::sdk::Vector<S>") const {
    std::string text;
    for (const char letter : letters_) text += (text.empty() ? "" : ", ") + ("[[maybe_unused]] " + type + " ") + letter;
    return text;
  }

  std::string emit(const Node& node) {
    switch (node.kind) {
      case Node::Kind::number:
        return literal(node.value);
      case Node::Kind::variable:
        return node.name + "[" + std::to_string(node.index) + "]";
      case Node::Kind::parameter:
        return "parameter_" + node.name;
      case Node::Kind::pi:
        return literal(3.141592653589793);
      case Node::Kind::call: {
        // The derivative rules take their arguments as S: some may be plain numbers, others S.
        std::string text = "::nonsep::sdk::" + node.name + (is_derivative_rule(node.name) ? "<S>(" : "(");
        for (std::size_t i = 0; i < node.operands.size(); ++i) text += (i == 0 ? "" : ", ") + emit(node.operands[i]);
        return text + ")";
      }
      case Node::Kind::negate:
        return "(-" + emit(node.operands[0]) + ")";
      case Node::Kind::power: {
        const std::string base = emit(node.operands[0]);
        if (const auto n = small_integer(node.operands[1])) {
          const std::string product = "integer_power<" + std::to_string(*n < 0 ? -*n : *n) + ">(" + base + ")";
          return *n < 0 ? "(1.0 / " + product + ")" : product;
        }
        return "::nonsep::sdk::pow(" + base + ", " + emit(node.operands[1]) + ")";
      }
      case Node::Kind::sum: {
        std::vector<Term> terms;
        for (std::size_t i = 0; i < node.operands.size(); ++i)
          terms.push_back({node.signs[i], emit(node.operands[i]), node_count(node.operands[i])});
        return combine(terms, '+');
      }
      case Node::Kind::product:
        return emit_product(node);
    }
    return {};
  }

 private:
  struct Term {
    char sign;  // + - * /
    std::string text;
    std::size_t nodes;
  };

  // A product with each repeated factor written once, as a power: x*x*...*x (k times) is integer_power<k>(x) for
  // k <= 64, pow(x, k) beyond, so the C++ (and the automatic derivatives the SDK makes of it) grows with the distinct
  // factors, not with the formula's length. Factors keep the order of their first appearance.
  std::string emit_product(const Node& node) {
    std::vector<std::pair<std::size_t, std::size_t>> groups;  // (first operand, count)
    for (std::size_t i = 0; i < node.operands.size(); ++i) {
      const auto same = std::find_if(groups.begin(), groups.end(), [&](const auto& group) {
        return node.signs[group.first] == node.signs[i] && node.operands[group.first] == node.operands[i];
      });
      if (same != groups.end())
        ++same->second;
      else
        groups.emplace_back(i, 1);
    }
    std::vector<Term> factors;
    for (const auto& [first, count] : groups) {
      const std::string factor = emit(node.operands[first]);
      factors.push_back({node.signs[first],
                         count == 1    ? factor
                         : count <= 64 ? "integer_power<" + std::to_string(count) + ">(S(" + factor + "))"
                                       : "::nonsep::sdk::pow(S(" + factor + "), " + literal(count) + ")",
                         node_count(node.operands[first]) + 1});
    }
    return combine(factors, '*');
  }

  // `terms` joined by their signs ('+' or '*' for the first is left out, '-' and '/' kept); beyond max_part_nodes in
  // all, runs of consecutive terms of at most max_part_nodes nodes, each a part, joined by `join`.
  std::string combine(const std::vector<Term>& terms, char join) {
    std::size_t nodes = 0;
    for (const Term& term : terms) nodes += term.nodes;
    if (nodes <= max_part_nodes) return joined(terms.begin(), terms.end());
    std::string text = "(";
    for (auto first = terms.begin(); first != terms.end();) {
      auto last = first;
      std::size_t run = 0;
      for (; last != terms.end() && (last == first || run + last->nodes <= max_part_nodes); ++last) run += last->nodes;
      // A term larger than a part on its own is written in place: its own sums and products are cut the same way.
      const std::string run_text = run <= max_part_nodes ? part(joined(first, last)) : joined(first, last);
      text += (first == terms.begin() ? "" : std::string(" ") + join + " ") + run_text;
      first = last;
    }
    return text + ")";
  }

  static std::string joined(std::vector<Term>::const_iterator first, std::vector<Term>::const_iterator last) {
    std::string text = "(";
    for (auto term = first; term != last; ++term) {
      if (term != first)
        text += std::string(" ") + term->sign + " ";
      else if (term->sign == '-')
        text += "-";
      else if (term->sign == '/')
        text += "1.0 / ";
      text += term->text;
    }
    return text + ")";
  }

  // A new part returning `text`, and its call.
  std::string part(const std::string& text) {
    const std::string name = "part_" + std::to_string(count_++);
    parts_ += "  template <class S>\n  [[gnu::noinline]] S " + name + "(" + parameters() + ") const {\n    return S(" +
              text + ");\n  }\n";
    std::string arguments;
    for (const char letter : letters_) arguments += (arguments.empty() ? "" : ", ") + std::string(1, letter);
    return name + "<S>(" + arguments + ")";
  }

  std::string letters_;
  std::string& parts_;
  std::size_t& count_;
};

// The gradient of `tree` as a template over the number type (the SDK differentiates it for the Hessians and the
// third derivatives), one line per component: d tree / d x_i written from derivative(), 0 where it is zero; or the
// components as given (`given`, "dT" or "dV", when not empty). Nothing when a written-out gradient would outgrow the
// tree (gradient_is_written): the SDK then differentiates the function itself.
std::string gradient(const char* function, const Node& tree, const std::vector<Node>& given, ExpressionWriter writer,
                     std::size_t dimension) {
  std::vector<std::optional<Node>> components;
  for (std::size_t i = 0; i < dimension; ++i)
    components.push_back(given.empty() ? derivative(tree, i) : std::optional<Node>(given[i]));
  if (given.empty() && !gradient_is_written(tree, components)) return "";
  std::string text = std::string("  template <class S>\n  void ") + function + "(" + writer.parameters() +
                     ", std::span<S> out) const {\n";
  for (std::size_t i = 0; i < dimension; ++i)
    text += "    out[" + std::to_string(i) + "] = S(" + (components[i] ? writer.emit(*components[i]) : "0.0") + ");\n";
  return text + "  }\n";
}

// The gradient of H(q, p), written out as gradient() writes grad_T (hamiltonian_adapter.hpp's grad_H, in doubles;
// the SDK differentiates H itself for the Hessian-vector products), or nothing when it would outgrow the tree.
std::string hamiltonian_gradient(const Node& tree, ExpressionWriter writer, std::size_t dimension) {
  std::vector<std::optional<Node>> components;
  for (const char letter : {'q', 'p'})
    for (std::size_t i = 0; i < dimension; ++i) components.push_back(derivative(tree, i, letter));
  if (!gradient_is_written(tree, components)) return "";
  std::string text = "  void grad_H(" + writer.parameters("nonsep::sdk::Vector<double>") +
                     ", std::span<double> dH_dq, std::span<double> dH_dp) const {\n    using S = double;\n";
  for (std::size_t k = 0; k < components.size(); ++k)
    text += std::string("    ") + (k < dimension ? "dH_dq[" : "dH_dp[") + std::to_string(k % dimension) + "] = S(" +
            (components[k] ? writer.emit(*components[k]) : "0.0") + ");\n";
  return text + "  }\n";
}

// T, V (or H) as a template: the formula, or, for one given by its gradient, an evaluation error (H_TTV and H_VVT never
// need the value; the gradient check and `inspect --check` skip what throws).
std::string function(const char* name, const Node& tree, const std::vector<Node>& given, ExpressionWriter writer) {
  const std::string head = std::string("  template <class S>\n  S ") + name + "(" + writer.parameters() + ") const {\n";
  if (!given.empty())
    return head + "    throw nonsep::sdk::EvaluationError(\"" + name + " is given by its gradient d" + name +
           " only: its value is not known (H needs only the gradient and the Hessian)\");\n  }\n";
  return head + "    return S(" + writer.emit(tree) + ");\n  }\n";
}

}  // namespace

bool gradient_is_written(const Node& tree, const std::vector<std::optional<Node>>& components) {
  std::size_t written = 0;
  for (const auto& component : components) written += component ? node_count(*component) : 1;
  return written <= max_gradient_growth * node_count(tree) + max_gradient_slack;
}

std::string cpp_source(const FormulaModel& model) {
  const std::string formulas =
      model.h_tree
          ? "H = " + model.H
          : (model.t_gradient.empty() ? "T = " : "") + model.T + ", " + (model.v_gradient.empty() ? "V = " : "") +
                model.V + (model.k_tree ? ", K = " + model.K : "") + (model.u_tree ? ", U = " + model.U : "");
  std::string source =
      "// A formula model, generated by nonsep from " + formulas +
      "\n#include <cstddef>\n#include <span>\n#include <nonsep/plugin_sdk.hpp>\n\nnamespace {\n\n"
      "// x^N as products: x^2 = x*x, x^3 = x*x*x, x^4 = (x*x)*(x*x), ... (inlined, as the dual numbers' arithmetic)\n"
      "template <int N, class S>\nNONSEP_SDK_DUAL_INLINE S integer_power(const S& x) {\n"
      "  if constexpr (N == 0) {\n    return S(1.0);\n  } else if constexpr (N == 1) {\n    return x;\n"
      "  } else if constexpr (N == 3) {\n    return x * x * x;\n  } else {\n"
      "    const S half = integer_power<N / 2>(x);\n"
      "    if constexpr (N % 2 == 0) {\n      return half * half;\n    } else {\n      return half * half * x;\n"
      "    }\n  }\n}\n\n"
      "struct Formula {\n  static constexpr std::size_t dimension = " +
      std::to_string(model.dimension) + ";\n";
  if (!model.parameters.empty()) {
    source += "  static constexpr nonsep::sdk::Parameter parameters[] = {\n";
    for (const FormulaParameter& parameter : model.parameters)
      source += "      {.name = \"" + parameter.name +
                "\", .type = nonsep::sdk::ParameterType::number, .default_value = " + literal(parameter.value) +
                (parameter.minimum ? ", .minimum = " + literal(*parameter.minimum) : std::string()) +
                (parameter.maximum ? ", .maximum = " + literal(*parameter.maximum) : std::string()) +
                ", .description = \"" + formula_parameter_description + "\"},\n";
    source += "  };\n  explicit Formula(const nonsep::sdk::ParameterValues& values)\n      : ";
    for (std::size_t i = 0; i < model.parameters.size(); ++i)
      source += (i == 0 ? "" : ", ") + std::string("parameter_") + model.parameters[i].name + "(values.number(\"" +
                model.parameters[i].name + "\"))";
    source += " {}\n";
    for (const auto& parameter : model.parameters) source += "  double parameter_" + parameter.name + ";\n";
  }
  std::string parts;
  std::size_t part_count = 0;
  if (model.h_tree) {
    const ExpressionWriter qp("qp", parts, part_count);
    source += function("H", *model.h_tree, {}, qp);
    source += hamiltonian_gradient(*model.h_tree, qp, model.dimension);
    source += parts;
    source += "};\n\n}  // namespace\n\n";
    source += "NONSEP_EXPORT_HAMILTONIAN(Formula, \"" + model.name + "\", \"1.0.0\", \"A formula model: " + formulas +
              "\", \"" + formulas + "\");\n";
    return source;
  }
  const ExpressionWriter p("p", parts, part_count), q("q", parts, part_count);
  source += function("T", model.t_tree, model.t_gradient, p);
  source += function("V", model.v_tree, model.v_gradient, q);
  if (model.k_tree) source += function("K", *model.k_tree, {}, p);
  if (model.u_tree) source += function("U", *model.u_tree, {}, q);
  source += gradient("grad_T", model.t_tree, model.t_gradient, p, model.dimension);
  source += gradient("grad_V", model.v_tree, model.v_gradient, q, model.dimension);
  if (model.k_tree) source += gradient("grad_K", *model.k_tree, {}, p, model.dimension);
  if (model.u_tree) source += gradient("grad_U", *model.u_tree, {}, q, model.dimension);
  source += parts;
  source += "};\n\n}  // namespace\n\n";
  source += "NONSEP_EXPORT_MODEL(Formula, \"" + model.name + "\", \"1.0.0\", \"A formula model: " + formulas +
            "\", \"" + formulas + "\");\n";
  return source;
}

}  // namespace nonsep::host::formula
