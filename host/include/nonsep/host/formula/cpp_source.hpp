#pragma once
// The C++ source of a formula model: a model class for the plugin SDK (nonsep/plugin_sdk.hpp, model_adapter.hpp)
// written from the parsed trees alone, with T and V templates over the number type, their gradients written from
// the trees' derivatives (derivative.hpp) as templates too (so the SDK differentiates the gradients, not T and V, for
// the Hessians and third derivatives; the same for K and U when the model has them), a fixed dimension, the parameter
// table (numbers with the formula's defaults) and metadata whose description and Hamiltonian are the canonical
// formulas. Integer powers x^n (|n| <= 64) are products (the SDK's square and cube are the same products); other powers
// are pow. The text depends on the model only, so it is the cache key's first part (plugin_cache.hpp).
#include <string>

#include "nonsep/host/formula/formula_model.hpp"

namespace nonsep::host::formula {

std::string cpp_source(const FormulaModel& model);

}  // namespace nonsep::host::formula
