// The scheme catalogue (scheme_catalogue.hpp): each entry's description, orders, options and factory.
#include "nonsep/core/schemes/scheme_catalogue.hpp"

#include <array>
#include <cmath>
#include <cstdio>

#include "nonsep/core/schemes/integrator.hpp"

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

ParameterDescription number_parameter(const std::string& name, const std::string& default_text,
                                      const std::string& description) {
  return {name, ParameterDescription::Kind::Number, default_text, description, false};
}
ParameterDescription max_iterations_parameter() {
  return number_parameter("max_iterations", std::to_string(GaussLegendre::default_max_iterations),
                          "most fixed-point iterations per step, an integer >= 1; a state that has not converged by "
                          "then retires as failed, with the reason");
}

// A whole number held in a double option (stages, max_iterations), or InvalidArgument naming it.
int whole_number(double value, const std::string& name) {
  if (!std::isfinite(value) || value != std::floor(value) || std::abs(value) > 1e9)
    throw InvalidArgument(name + " must be a whole number (found " + std::to_string(value) + ")");
  return static_cast<int>(value);
}

// Tao's order: 2, 4 or 6 (the Strang step and its triple jumps).
int tao_order(const Fraction& order) {
  if (order.denominator() != 1 || (order.numerator() != 2 && order.numerator() != 4 && order.numerator() != 6))
    throw InvalidArgument("Tao's extended phase-space integrator has orders 2, 4 and 6 (found " + order.to_string() +
                          ")");
  return static_cast<int>(order.numerator());
}

int chin_index(const IntegratorSpec& spec, int highest, const char* name) {
  return chin_order_index(spec.order, highest, name);
}

const std::string comparator_cost_note =
    " Needs the plugin's Hessians and third derivatives (one grad H = grad T or V, two Hessians, one d3 "
    "contraction); its tangent map (Lyapunov/MEGNO) also the directional derivative of grad H (hvp_H, plugin ABI "
    "version 5).";

constexpr int triplet_orders = TripletComposition<>::max_levels + 1;  // order 2j/3 has j - 1 levels
constexpr int mpe_orders = MultiProductExpansion<>::max_terms;        // order 2m/3 has m terms
}  // namespace

std::span<const Scheme> scheme_catalogue() {
  static const std::array<Scheme, 6> catalogue = {
      Scheme{{"basic",
              "Chin basic 9-stage splitting",
              "eq. (expalg)",
              "One palindromic 9-stage splitting of the separable T(p) + V(q) with eps = cbrt(dt); solves H_TTV "
              "(or H_VVT with T and V interchanged). Order 2/3; 4 grad T + 4 grad V evaluations per step.",
              "chin",
              true,
              true,
              {order_parameter("2/3", "only 2/3 exists"), t2_parameter()},
              1,
              {}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               SeparableBasicStep base(ChinBasicStep(spec.form, spec.t2));
               chin_index(spec, 1, "basic");
               return base;
             }},
      Scheme{{"triplet",
              "Triplet composition of the basic step",
              "eqs. (sym43), (sym63), applied recursively",
              "T_{(k+2)/3}(dt) = T_{k/3}(dt/(2-s)) T_{k/3}(-s dt/(2-s)) T_{k/3}(dt/(2-s)), s = 2^(3/(k+3)). "
              "Symplectic and time-reversible; order 2j/3 costs 3^(j-1) basic steps per step.",
              "chin",
              true,
              true,
              {order_parameter_up_to("4/3", triplet_orders), t2_parameter()},
              triplet_orders,
              {}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               SeparableBasicStep base(ChinBasicStep(spec.form, spec.t2));
               return TripletComposition<SeparableBasicStep>(std::move(base),
                                                             chin_index(spec, triplet_orders, "triplet") - 1);
             }},
      Scheme{{"mpe",
              "Multi-product expansion of the basic step",
              "eqs. (mpe43), (mpe63), any number of terms",
              "sum_i c_i T^i(dt/i), c_i = prod_{j != i} i^n/(i^n - j^n), n = 2/3. Not symplectic, not exactly "
              "time-reversible; order 2m/3 with m terms costs m(m+1)/2 basic steps per step.",
              "chin",
              false,
              false,
              {order_parameter_up_to("4/3", mpe_orders), t2_parameter()},
              mpe_orders,
              {}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               SeparableBasicStep base(ChinBasicStep(spec.form, spec.t2));
               return MultiProductExpansion<SeparableBasicStep>(std::move(base), chin_index(spec, mpe_orders, "mpe"));
             }},
      Scheme{{"tao",
              "Tao's explicit symplectic integrator in extended phase space (comparator)",
              "M. Tao, Phys. Rev. E 94, 043303 (2016)",
              "Two copies (q, p), (x, y) bound by omega |(q, p) - (x, y)|^2 / 2; Strang splitting of the three "
              "exactly solvable parts (order 2), triple jumps for 4 and 6. Explicit; symplectic and symmetric on "
              "the extended phase space, not on (q, p) alone. Cost 3^(order/2) grad H per step plus 1 at the "
              "start. Reports the largest distance between the copies (summary.json comparator.max_copy_distance)." +
                  comparator_cost_note,
              "comparator",
              true,
              true,
              {order_parameter("2", "2, 4 or 6"),
               number_parameter("omega", "20",
                                "binding of the two copies, finite and > 0; Tao's error bound grows "
                                "with omega and needs dt << omega^(-1/order)")},
              1,
              {Fraction(2), Fraction(4), Fraction(6)}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               return TaoExtendedPhaseSpace(spec.form, tao_order(spec.order), spec.omega);
             }},
      Scheme{{"implicit_midpoint",
              "Implicit midpoint rule (comparator)",
              "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VIII.6",
              "z' = z + dt f((z + z')/2), Gauss-Legendre with 1 stage; order 2, symplectic and symmetric. Solved by "
              "fixed-point iteration from Z = 0 (no Newton), 1 grad H per state per iteration. Stopping rule per "
              "state: converged when the relative change of the stages is <= 1 ulp, or stops decreasing while "
              "<= 64 ulp; failed when an iterate is not finite or after max_iterations: the trajectory then "
              "retires with status failed and the reason, never with an inaccurate step." +
                  comparator_cost_note,
              "comparator",
              true,
              true,
              {max_iterations_parameter()},
              1,
              {Fraction(2)}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               return GaussLegendre(spec.form, 2, whole_number(spec.max_iterations, "max_iterations"));
             }},
      Scheme{{"gauss",
              "Gauss-Legendre collocation (comparator)",
              "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VI.4, VIII.6",
              "s-stage Gauss-Legendre Runge-Kutta method on Hamilton's equations of H, order 2s; symplectic and "
              "symmetric. Fixed-point iteration from Z = 0 (no Newton), s grad H per state per iteration, with the "
              "stopping rule of implicit_midpoint (non-convergence retires the trajectory as failed)." +
                  comparator_cost_note,
              "comparator",
              true,
              true,
              {number_parameter("stages", "2", "number of stages s: 1, 2 or 3 (orders 2, 4, 6)"),
               max_iterations_parameter()},
              1,
              {Fraction(2), Fraction(4), Fraction(6)}},
             [](const IntegratorSpec& spec) -> SchemeStepper {
               const int stages = whole_number(spec.stages, "stages");
               if (stages < 1 || stages > 3)
                 throw InvalidArgument("Gauss-Legendre collocation has 1, 2 or 3 stages (orders 2, 4, 6); found " +
                                       std::to_string(stages));
               return GaussLegendre(spec.form, 2 * stages, whole_number(spec.max_iterations, "max_iterations"));
             }},
  };
  return catalogue;
}

const Scheme* find_scheme(const std::string& name) {
  for (const auto& scheme : scheme_catalogue())
    if (scheme.name == name) return &scheme;
  return nullptr;
}

}  // namespace nonsep
