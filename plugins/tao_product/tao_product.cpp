#include "tao_product.hpp"

NONSEP_EXPORT_MODEL(TaoProduct, "tao_product", "1.0.0", "H = (q^2 + 1)(p^2 + 1)/2 in Chin's product form",
                    "T = (p sqrt(1 + p^2) + asinh p)/(2 sqrt 2), V = q^2/2 + q^4/12; "
                    "H_TTV = T'(p)^2 V''(q) = (1 + p^2)(1 + q^2)/2");
