// The canonical printer of expression.hpp: a parsed tree written back as text, with the parentheses it needs and no
// others, so that parsing the printed text gives the same tree.
#include <charconv>
#include <string>

#include "nonsep/host/formula/expression.hpp"

namespace nonsep::host::formula {

namespace {

std::string number_text(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

bool is_primary(const Node& node) {
  return node.kind == Node::Kind::number || node.kind == Node::Kind::variable || node.kind == Node::Kind::parameter ||
         node.kind == Node::Kind::pi || node.kind == Node::Kind::call;
}

std::string print_node(const Node& node);

std::string parenthesized(const Node& node, bool needed) {
  return needed ? "(" + print_node(node) + ")" : print_node(node);
}

std::string print_node(const Node& node) {
  switch (node.kind) {
    case Node::Kind::number:
      return number_text(node.value);
    case Node::Kind::variable:
      return node.name + std::to_string(node.index);
    case Node::Kind::parameter:
      return node.name;
    case Node::Kind::pi:
      return "pi";
    case Node::Kind::call: {
      std::string text = node.name + "(";
      for (std::size_t i = 0; i < node.operands.size(); ++i)
        text += (i == 0 ? "" : ", ") + print_node(node.operands[i]);
      return text + ")";
    }
    case Node::Kind::negate:
      return "-" + parenthesized(node.operands[0], !is_primary(node.operands[0]) &&
                                                       node.operands[0].kind != Node::Kind::power &&
                                                       node.operands[0].kind != Node::Kind::negate);
    case Node::Kind::power: {
      const Node& exponent = node.operands[1];
      return parenthesized(node.operands[0], !is_primary(node.operands[0])) + "^" +
             parenthesized(exponent, exponent.kind == Node::Kind::sum || exponent.kind == Node::Kind::product);
    }
    case Node::Kind::sum: {
      std::string text;
      for (std::size_t i = 0; i < node.operands.size(); ++i)
        text += (i == 0 ? "" : std::string(" ") + node.signs[i] + " ") +
                parenthesized(node.operands[i], node.operands[i].kind == Node::Kind::sum);
      return text;
    }
    case Node::Kind::product: {
      std::string text;
      for (std::size_t i = 0; i < node.operands.size(); ++i)
        text += (i == 0 ? "" : std::string(1, node.signs[i])) +
                parenthesized(node.operands[i],
                              node.operands[i].kind == Node::Kind::sum || node.operands[i].kind == Node::Kind::product);
      return text;
    }
  }
  return {};
}

}  // namespace

std::string print(const Node& tree) { return print_node(tree); }

}  // namespace nonsep::host::formula
