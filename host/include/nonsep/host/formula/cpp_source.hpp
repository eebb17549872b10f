#pragma once
// The C++ source of a formula model: a model class for the plugin SDK (nonsep/plugin_sdk.hpp, model_adapter.hpp)
// written from the parsed trees alone, with T and V templates over the number type, their gradients written from
// the trees' derivatives (derivative.hpp) as templates too (so the SDK differentiates the gradients, not T and V, for
// the Hessians and third derivatives; the same for K and U when the model has them), a fixed dimension, the parameter
// table (numbers with the formula's defaults) and metadata whose description and Hamiltonian are the canonical
// formulas. A gradient is written out only while it stays small beside its function: at most max_gradient_growth
// times the function's nodes plus max_gradient_slack (a product of n factors has a derivative of n(n-1) factors,
// which grows the C++ and the compile quadratically); beyond that the plugin leaves the gradient to the SDK's
// automatic differentiation of the function, whose C++ grows linearly with the formula. A sum or product of more
// than max_part_nodes tree nodes is cut into parts of at most that many, each a function the compiler does not
// inline, so that no function it optimises outgrows that bound and the compile time grows linearly with the formula
// (docs/formula-models.md, "Long formulas"). A factor repeated in a product is written once, as a power. Integer
// powers x^n
// (|n| <= 64) are products (the SDK's square and cube are the same products); other powers are pow. The text depends on
// the model only, so it is the cache key's first part (plugin_cache.hpp).
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/formula/formula_model.hpp"

namespace nonsep::host::formula {

inline constexpr std::size_t max_gradient_growth = 8;
inline constexpr std::size_t max_gradient_slack = 256;
inline constexpr std::size_t max_part_nodes = 64;

// Whether the gradient `components` (derivative() of `tree` per variable; nothing where zero) is written out.
bool gradient_is_written(const Node& tree, const std::vector<std::optional<Node>>& components);

std::string cpp_source(const FormulaModel& model);

}  // namespace nonsep::host::formula
