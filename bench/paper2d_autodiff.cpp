// The shipped paper2d model exported with automatic derivatives everywhere (its written-out gradients, products and
// third derivatives ignored): the model as a user writes it with templated T and V only, for bench/autodiff_megno.py.
#include "paper2d/paper2d.hpp"

NONSEP_EXPORT_MODEL_WITH_DERIVATIVES(Paper2D, ::nonsep::sdk::Derivatives::automatic, "paper2d_autodiff", "1.0.0",
                                     "paper2d with derivatives by automatic differentiation only (benchmark)",
                                     "T = p1 + p2 + (p1^3 + p2^3)/6, V = |q|^2/2 + |q|^4/12 + coupling q1^2 q2^2");
