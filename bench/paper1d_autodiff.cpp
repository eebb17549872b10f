// The shipped paper1d model exported with automatic derivatives everywhere (its analytic gradients ignored), so
// that the benchmark can compare AD with analytic gradients through the same plugin boundary.
#include "paper1d/paper1d.hpp"

NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Paper1D, ::nonsep::sdk::Derivatives::automatic, "paper1d_autodiff", "1.0.0",
                                     "paper1d with derivatives by automatic differentiation only (benchmark)",
                                     "T = p + p^3/6, V = q^2/2 + q^4/12; H_TTV = (1 + p^2/2)^2 (1 + q^2)");
