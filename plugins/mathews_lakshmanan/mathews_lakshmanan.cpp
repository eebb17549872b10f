#include "mathews_lakshmanan.hpp"

NONSEP_EXPORT_MODEL(MathewsLakshmanan, "mathews_lakshmanan", "1.0.0",
                    "The Mathews-Lakshmanan oscillator: a position-dependent inverse mass with a potential, with an "
                    "exact solution q = A sin(omega t + phi)",
                    "T = p^2/2, V = q^2/4 + lambda q^4/24, U = (1/2) alpha^2 q^2/(1 + lambda q^2); "
                    "H_TTV + U = (1/2)(1 + lambda q^2) p^2 + (1/2) alpha^2 q^2/(1 + lambda q^2)");
