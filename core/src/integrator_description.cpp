#include "nonsep/core/integrator_description.hpp"

#include <array>
#include <cmath>
#include <cstdio>

#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/core/error.hpp"
#include "nonsep/core/multi_product_expansion.hpp"
#include "nonsep/core/triplet_composition.hpp"

namespace nonsep {

namespace {
std::string default_t2_text() {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", ChinCoefficients::default_t2());
  return buffer;
}

ParameterDescription t2_parameter() {
  return {"t2", ParameterDescription::Kind::Number, default_t2_text(),
          "free coefficient of the basic step, any finite non-zero number; t1 = -t2, v1 = 1/t2^2, "
          "v2 = -v1/2, v0 = -2(v1+v2). The default -6^(1/3) makes e_TTTTV = e_VTTTV; the paper uses -2 for "
          "Figure 1 and about -3 for Figure 2"};
}

ParameterDescription order_parameter(const std::string& default_order, const std::string& which) {
  return {"order", ParameterDescription::Kind::Order, default_order,
          "order of convergence as an exact fraction; " + which};
}

std::string orders_list() { return "2/3, 4/3, 2, 8/3, 10/3, 4, ... (2j/3 for j = 1, 2, 3, ...)"; }
}  // namespace

std::span<const SchemeDescription> scheme_catalogue() {
  static const std::array<SchemeDescription, 3> catalogue = {
      SchemeDescription{
          "basic", "Chin basic 9-stage splitting", "eq. (expalg)",
          "One palindromic 9-stage splitting of the separable T(p) + V(q) with eps = cbrt(dt); solves H_TTV "
          "(or H_VVT with T and V interchanged). Order 2/3; 4 grad T + 4 grad V evaluations per step.",
          true, true, {order_parameter("2/3", "only 2/3 exists"), t2_parameter()}},
      SchemeDescription{
          "triplet", "Triplet composition of the basic step", "eqs. (sym43), (sym63), applied recursively",
          "T_{(k+2)/3}(dt) = T_{k/3}(dt/(2-s)) T_{k/3}(-s dt/(2-s)) T_{k/3}(dt/(2-s)), s = 2^(3/(k+3)). "
          "Symplectic and time-reversible; order 2j/3 costs 3^(j-1) basic steps per step.",
          true, true,
          {order_parameter("4/3", "any of " + orders_list() + " up to " +
                                      Fraction(2 * (TripletComposition<>::max_levels + 1), 3).to_string()),
           t2_parameter()}},
      SchemeDescription{
          "mpe", "Multi-product expansion of the basic step", "eqs. (mpe43), (mpe63), any number of terms",
          "sum_i c_i T^i(dt/i), c_i = prod_{j != i} i^n/(i^n - j^n), n = 2/3. Not symplectic, not exactly "
          "time-reversible; order 2m/3 with m terms costs m(m+1)/2 basic steps per step.",
          false, false,
          {order_parameter("4/3", "any of " + orders_list() + " up to " +
                                      Fraction(2 * MultiProductExpansion<>::max_terms, 3).to_string()),
           t2_parameter()}},
  };
  return catalogue;
}

std::optional<SchemeDescription> find_scheme(const std::string& name) {
  for (const auto& scheme : scheme_catalogue())
    if (scheme.name == name) return scheme;
  return std::nullopt;
}

int chin_order_index(const Fraction& order, int max_j, const std::string& what) {
  // order = a/b = 2j/3 in lowest terms: a = 2j, b = 3 when 3 does not divide j; a = 2j/3, b = 1 when it does. So
  // a is positive and even, b is 1 or 3, and j = 3a/2 or a/2. Divisions only: a may be as large as int64 allows.
  const std::int64_t a = order.numerator();
  const std::int64_t b = order.denominator();
  if (a <= 0 || a % 2 != 0 || (b != 1 && b != 3))
    throw InvalidArgument("order " + order.to_string() + " does not exist for " + what + "; the orders are " +
                          orders_list());
  const std::int64_t half = a / 2;
  const bool beyond = b == 1 ? half > max_j / 3 : half > max_j;
  const std::int64_t j = beyond ? std::int64_t{max_j} + 1 : (b == 1 ? 3 * half : half);
  if (j > max_j)
    throw InvalidArgument("order " + order.to_string() + " is beyond the highest order of " + what + ", " +
                          Fraction(2 * max_j, 3).to_string());
  return static_cast<int>(j);
}

}  // namespace nonsep
