#pragma once
// The paper's schemes as the runtime-chosen integrators offer them (stepper.hpp): the basic step (eq. (expalg)),
// its triplet composition (eqs. (sym43), (sym63)) and its multi-product expansion (eqs. (mpe43), (mpe63)), each
// built over the basic step with the separable flows of K(p) + U(q) around it (separable_composition.hpp), which is
// the basic step itself for a model without them. They share their options, the order and t2, and differ in the
// default order: 2/3 for the basic step (ChinOptions{}), 4/3 for the compositions (their defaults()).
#include <string>
#include <tuple>
#include <vector>

#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/core/schemes/scheme_options.hpp"
#include "nonsep/core/schemes/separable_composition.hpp"
#include "nonsep/core/schemes/triplet_composition.hpp"

namespace nonsep {

struct ChinOptions {
  Fraction order = Fraction(2, 3);  // 2j/3; which j a scheme has, its catalogue entry says
  double t2 = ChinCoefficients::default_t2();
  static constexpr auto members() {
    return std::tuple{option("order", &ChinOptions::order),
                      option("t2", &ChinOptions::t2,
                             "free coefficient of the basic step, any finite non-zero number; t1 = -t2, v1 = 1/t2^2, "
                             "v2 = -v1/2, v0 = -2(v1+v2). The default -6^(1/3) makes e_TTTTV = e_VTTTV; the paper "
                             "uses -2 for Figure 1 and about -3 for Figure 2",
                             true)};
  }
};

namespace chin_scheme {
// The catalogue's options of a Chin scheme with `defaults` and orders 2j/3 up to j = highest_order_index.
inline std::vector<ParameterDescription> options(const ChinOptions& defaults, int highest_order_index) {
  return describe_options(defaults, highest_order_index == 1 ? "only 2/3 exists"
                                                             : "any of " + chin_orders_text() + " up to " +
                                                                   Fraction(2 * highest_order_index, 3).to_string());
}
// The description of the basic step of `options` (InvalidArgument for t2 = 0 or not finite): t2 is checked before
// the order.
inline IntegratorDescription base_description(const ChinOptions& options) {
  return ChinBasicStep::description(ChinCoefficients::from_t2(options.t2).t2);
}
// The basic step of `options`, checked by its scheme's describe().
inline SeparableBasicStep base(const ChinOptions& options, HamiltonianForm form) {
  return SeparableBasicStep(ChinBasicStep(form, options.t2));
}
}  // namespace chin_scheme

struct BasicScheme {
  using Options = ChinOptions;
  using Stepper = SeparableBasicStep;
  static SchemeDescription description() {
    return {.name = "basic",
            .method = "Chin basic 9-stage splitting",
            .equations = "eq. (expalg)",
            .summary =
                "One palindromic 9-stage splitting of the separable T(p) + V(q) with eps = cbrt(dt); solves H_TTV "
                "(or H_VVT with T and V interchanged). Order 2/3; 4 grad T + 4 grad V evaluations per step.",
            .family = "chin",
            .symplectic = true,
            .time_reversible = true,
            .parameters = chin_scheme::options(ChinOptions{}, 1),
            .highest_order_index = 1,
            .comparator_orders = {},
            .auto_orders = {}};
  }
  // What the scheme of `options` is, without building it; InvalidArgument for an option it refuses.
  static IntegratorDescription describe(const Options& options) {
    IntegratorDescription d = chin_scheme::base_description(options);
    chin_order_index(options.order, 1, "basic");
    return d;
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    describe(options);
    return chin_scheme::base(options, form);
  }
};

struct TripletScheme {
  using Options = ChinOptions;
  using Stepper = TripletComposition<SeparableBasicStep>;
  static constexpr int orders = Stepper::max_levels + 1;  // order 2j/3 has j - 1 levels
  static Options defaults() { return {Fraction(4, 3)}; }
  static SchemeDescription description() {
    return {.name = "triplet",
            .method = "Triplet composition of the basic step",
            .equations = "eqs. (sym43), (sym63), applied recursively",
            .summary =
                "T_{(k+2)/3}(dt) = T_{k/3}(dt/(2-s)) T_{k/3}(-s dt/(2-s)) T_{k/3}(dt/(2-s)), s = 2^(3/(k+3)). "
                "Symplectic and time-reversible; order 2j/3 costs 3^(j-1) basic steps per step.",
            .family = "chin",
            .symplectic = true,
            .time_reversible = true,
            .parameters = chin_scheme::options(defaults(), orders),
            .highest_order_index = orders,
            .comparator_orders = {},
            .auto_orders = {Fraction(8, 3), Fraction(2)}};
  }
  static IntegratorDescription describe(const Options& options) {
    const IntegratorDescription base = chin_scheme::base_description(options);
    return Stepper::description(base, levels(options));
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    describe(options);
    return Stepper(chin_scheme::base(options, form), levels(options));
  }
  static int levels(const Options& options) { return chin_order_index(options.order, orders, "triplet") - 1; }
};

struct MultiProductExpansionScheme {
  using Options = ChinOptions;
  using Stepper = MultiProductExpansion<SeparableBasicStep>;
  static constexpr int orders = Stepper::max_terms;  // order 2m/3 has m terms
  static Options defaults() { return {Fraction(4, 3)}; }
  static SchemeDescription description() {
    return {.name = "mpe",
            .method = "Multi-product expansion of the basic step",
            .equations = "eqs. (mpe43), (mpe63), any number of terms",
            .summary =
                "sum_i c_i T^i(dt/i), c_i = prod_{j != i} i^n/(i^n - j^n), n = 2/3. Not symplectic, not exactly "
                "time-reversible; order 2m/3 with m terms costs m(m+1)/2 basic steps per step.",
            .family = "chin",
            .symplectic = false,
            .time_reversible = false,
            .parameters = chin_scheme::options(defaults(), orders),
            .highest_order_index = orders,
            .comparator_orders = {},
            .auto_orders = {Fraction(4)}};
  }
  static IntegratorDescription describe(const Options& options) {
    const IntegratorDescription base = chin_scheme::base_description(options);
    return Stepper::description(base, terms(options));
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    describe(options);
    return Stepper(chin_scheme::base(options, form), terms(options));
  }
  static int terms(const Options& options) { return chin_order_index(options.order, orders, "mpe"); }
};

}  // namespace nonsep
