#pragma once
// Partial derivatives of a formula's tree (expression.hpp), written as trees again, so that a formula model's
// gradient is plain code (cpp_source.hpp) instead of automatic differentiation: the stepping kernels then inline
// the gradient as they inline a hand-written one, and the compiler has less to do.
//
// derivative(tree, i, letter) is d tree / d x_i for the variable x_i of that letter ('q' or 'p'; '\0' for a tree of
// one letter, T's or V's), or nothing when the tree does not depend on x_i (the derivative is zero everywhere). The
// rules are the chain rule and, for each function, the derivative the SDK's dual numbers use
// (plugins/sdk/include/nonsep/sdk/dual.hpp), with the same special cases: the functions whose special cases are rules
// of their own (log and log1p outside their domain, abs at 0, min and max at a tie, the exponent of pow at a base <= 0)
// are calls of the SDK's functions of the same rule (derivative_rule names them), so a formula model's gradient is the
// automatic one up to rounding, and non-finite at the same states. (Where automatic differentiation multiplies an
// infinite or NaN derivative, as of abs at 0, by another variable's zero derivative, it writes NaN in that variable's
// component too; the tree writes that component's own value. The gradient is non-finite either way, so a run diverges
// at the same step.)
//
// The trees are simplified as they are built (numbers folded in sums and products, zero terms and unit factors
// dropped, nested sums and products flattened), and depend only on the tree: the same formula gives the same code.
#include <cstddef>
#include <optional>
#include <string_view>

#include "nonsep/host/formula/expression.hpp"

namespace nonsep::host::formula {

std::optional<Node> derivative(const Node& tree, std::size_t index, char letter = '\0');

// Whether a call node names one of the SDK's derivative rules (log_derivative, min_derivative, ...), which only
// derivative() writes and the parser never accepts.
bool is_derivative_rule(std::string_view function);

}  // namespace nonsep::host::formula
