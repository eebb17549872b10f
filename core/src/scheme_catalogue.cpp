// The scheme catalogue (scheme_catalogue.hpp): each entry's description, orders, options and factory.
#include "nonsep/core/scheme_catalogue.hpp"

#include <array>
#include <cstdio>

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
          "Figure 1 and about -3 for Figure 2",
          true};
}

ParameterDescription order_parameter(const std::string& default_order, const std::string& which) {
  return {"order", ParameterDescription::Kind::Order, default_order,
          "order of convergence as an exact fraction; " + which, false};
}
ParameterDescription order_parameter_up_to(const std::string& default_order, int highest_order_index) {
  return order_parameter(default_order,
                         "any of " + chin_orders_text() + " up to " + Fraction(2 * highest_order_index, 3).to_string());
}

constexpr int triplet_orders = TripletComposition<>::max_levels + 1;  // order 2j/3 has j - 1 levels
constexpr int mpe_orders = MultiProductExpansion<>::max_terms;         // order 2m/3 has m terms
}  // namespace

std::span<const Scheme> scheme_catalogue() {
  static const std::array<Scheme, 3> catalogue = {
      Scheme{{"basic", "Chin basic 9-stage splitting", "eq. (expalg)",
              "One palindromic 9-stage splitting of the separable T(p) + V(q) with eps = cbrt(dt); solves H_TTV "
              "(or H_VVT with T and V interchanged). Order 2/3; 4 grad T + 4 grad V evaluations per step.",
              true, true, {order_parameter("2/3", "only 2/3 exists"), t2_parameter()}, 1},
             [](ChinBasicStep base, int) -> SchemeStepper { return base; }},
      Scheme{{"triplet", "Triplet composition of the basic step", "eqs. (sym43), (sym63), applied recursively",
              "T_{(k+2)/3}(dt) = T_{k/3}(dt/(2-s)) T_{k/3}(-s dt/(2-s)) T_{k/3}(dt/(2-s)), s = 2^(3/(k+3)). "
              "Symplectic and time-reversible; order 2j/3 costs 3^(j-1) basic steps per step.",
              true, true, {order_parameter_up_to("4/3", triplet_orders), t2_parameter()}, triplet_orders},
             [](ChinBasicStep base, int j) -> SchemeStepper { return TripletComposition<>(std::move(base), j - 1); }},
      Scheme{{"mpe", "Multi-product expansion of the basic step", "eqs. (mpe43), (mpe63), any number of terms",
              "sum_i c_i T^i(dt/i), c_i = prod_{j != i} i^n/(i^n - j^n), n = 2/3. Not symplectic, not exactly "
              "time-reversible; order 2m/3 with m terms costs m(m+1)/2 basic steps per step.",
              false, false, {order_parameter_up_to("4/3", mpe_orders), t2_parameter()}, mpe_orders},
             [](ChinBasicStep base, int m) -> SchemeStepper { return MultiProductExpansion<>(std::move(base), m); }},
  };
  return catalogue;
}

const Scheme* find_scheme(const std::string& name) {
  for (const auto& scheme : scheme_catalogue())
    if (scheme.name == name) return &scheme;
  return nullptr;
}

}  // namespace nonsep
