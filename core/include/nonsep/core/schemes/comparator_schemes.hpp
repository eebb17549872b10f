#pragma once
// The schemes of the family "comparator" as the runtime-chosen integrators offer them (stepper.hpp): Tao's extended
// phase space (tao_extended_phase_space.hpp) and Gauss-Legendre collocation (gauss_legendre.hpp), the implicit
// midpoint rule being its one-stage case. Unlike Chin's splittings of T(p) + V(q), they integrate H itself from its
// gradient (hamiltonian_gradient.hpp): their steppers step
// only a model with Hessians and third derivatives, and their tangent maps need the directional derivative of
// grad H.
#include <string>
#include <tuple>

#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/scheme_options.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"

namespace nonsep {

namespace comparator_scheme {
inline const std::string cost_note =
    " Needs the plugin's Hessians and third derivatives (one grad H = grad T or V, two Hessians, one d3 "
    "contraction); its tangent map (Lyapunov/MEGNO) also the directional derivative of grad H (hvp_H, plugin ABI "
    "version 5).";
inline constexpr const char* max_iterations_text =
    "most fixed-point iterations per step, an integer >= 1; a state that has not converged by then retires as "
    "failed, with the reason";
}  // namespace comparator_scheme

struct TaoOptions {
  Fraction order = Fraction(2);
  double omega = TaoExtendedPhaseSpace::default_omega;
  static constexpr auto members() {
    return std::tuple{option("order", &TaoOptions::order),
                      option("omega", &TaoOptions::omega,
                             "binding of the two copies, finite and > 0; Tao's error bound grows with omega and needs "
                             "dt << omega^(-1/order)")
                          .above(0)};
  }
};

struct TaoScheme {
  using Options = TaoOptions;
  using Stepper = TaoExtendedPhaseSpace;
  static SchemeDescription description() {
    return {.name = "tao",
            .method = "Tao's explicit symplectic integrator in extended phase space, for any H",
            .equations = "M. Tao, Phys. Rev. E 94, 043303 (2016)",
            .summary =
                "Two copies (q, p), (x, y) bound by omega |(q, p) - (x, y)|^2 / 2; Strang splitting of the three "
                "exactly solvable parts (order 2), triple jumps for 4 and 6. Explicit; symplectic and symmetric on "
                "the extended phase space, not on (q, p) alone. Cost 3^(order/2) grad H per step plus 1 at the "
                "start. Reports the largest distance between the copies (summary.json comparator.max_copy_distance)." +
                comparator_scheme::cost_note,
            .family = "comparator",
            .symplectic = true,
            .time_reversible = true,
            .parameters = describe_options(TaoOptions{}, "2, 4 or 6"),
            .highest_order_index = 1,
            .comparator_orders = {Fraction(2), Fraction(4), Fraction(6)},
            .auto_orders = {}};
  }
  // Order 2, 4 or 6: the Strang step and its triple jumps.
  static IntegratorDescription describe(const Options& options) {
    return Stepper::description(order(options), options.omega).integrator_description();
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    return Stepper(form, order(options), options.omega);
  }
  // The order, checked with omega (InvalidArgument for either refused).
  static int order(const Options& options) {
    const Fraction& asked = options.order;
    if (asked.denominator() != 1 || (asked.numerator() != 2 && asked.numerator() != 4 && asked.numerator() != 6))
      throw InvalidArgument("Tao's extended phase-space integrator has orders 2, 4 and 6 (found " + asked.to_string() +
                            ")");
    Stepper::check(static_cast<int>(asked.numerator()), options.omega);
    return static_cast<int>(asked.numerator());
  }
};

struct ImplicitMidpointOptions {
  int max_iterations = GaussLegendre::default_max_iterations;
  static constexpr auto members() {
    return std::tuple{
        option("max_iterations", &ImplicitMidpointOptions::max_iterations, comparator_scheme::max_iterations_text)
            .at_least(1)};
  }
};

struct ImplicitMidpointScheme {
  using Options = ImplicitMidpointOptions;
  using Stepper = GaussLegendre;
  static SchemeDescription description() {
    return {.name = "implicit_midpoint",
            .method = "Implicit midpoint rule, for any H",
            .equations = "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VIII.6",
            .summary =
                "z' = z + dt f((z + z')/2), Gauss-Legendre with 1 stage; order 2, symplectic and symmetric. Solved by "
                "fixed-point iteration (no Newton) from the last step's stage extrapolated, 1 grad H per state per "
                "iteration. Stopping rule per state: converged when the relative change of the stages is <= 1 ulp, or "
                "stops decreasing while "
                "<= 64 ulp; failed when an iterate is not finite or after max_iterations: the trajectory then "
                "retires with status failed and the reason, never with an inaccurate step." +
                comparator_scheme::cost_note,
            .family = "comparator",
            .symplectic = true,
            .time_reversible = true,
            .parameters = describe_options(ImplicitMidpointOptions{}),
            .highest_order_index = 1,
            .comparator_orders = {Fraction(2)},
            .auto_orders = {}};
  }
  static IntegratorDescription describe(const Options& options) {
    Stepper::check(1, options.max_iterations);
    return Stepper::description(1, options.max_iterations).integrator_description();
  }
  static Stepper make(const Options& options, HamiltonianForm form) { return Stepper(form, 2, options.max_iterations); }
};

struct GaussOptions {
  int stages = 2;
  int max_iterations = GaussLegendre::default_max_iterations;
  static constexpr auto members() {
    return std::tuple{
        option("stages", &GaussOptions::stages, "number of stages s, 1 to 8 (orders 2 to 16)")
            .within(1, GaussLegendreTableau::max_stages),
        option("max_iterations", &GaussOptions::max_iterations, comparator_scheme::max_iterations_text).at_least(1)};
  }
};

struct GaussScheme {
  using Options = GaussOptions;
  using Stepper = GaussLegendre;
  static SchemeDescription description() {
    return {
        .name = "gauss",
        .method = "Gauss-Legendre collocation, for any H",
        .equations = "Hairer, Lubich, Wanner, Geometric Numerical Integration, II.1.3, VI.4, VIII.6",
        .summary =
            "s-stage Gauss-Legendre Runge-Kutta method on Hamilton's equations of H, order 2s; symplectic and "
            "symmetric, its coefficients arranged so that it stays symplectic in floating point (round-off in H grows "
            "like the square root of the steps). Fixed-point iteration (no Newton) from the last step's stages "
            "extrapolated, s grad H per state per iteration, with the "
            "stopping rule of implicit_midpoint (non-convergence retires the trajectory as failed). Implicit: a step "
            "costs more than an explicit one of the same order, but stays accurate at larger steps on strongly "
            "coupled or chaotic orbits, which makes it the safer choice for chaos maps (docs/dynamics.md)." +
            comparator_scheme::cost_note,
        .family = "comparator",
        .symplectic = true,
        .time_reversible = true,
        .parameters = describe_options(GaussOptions{}),
        .highest_order_index = 1,
        .comparator_orders = {Fraction(2), Fraction(4), Fraction(6), Fraction(8), Fraction(10), Fraction(12),
                              Fraction(14), Fraction(16)},
        .auto_orders = {Fraction(16), Fraction(8), Fraction(6), Fraction(4)}};
  }
  static IntegratorDescription describe(const Options& options) {
    Stepper::check(options.stages, options.max_iterations);
    return Stepper::description(options.stages, options.max_iterations).integrator_description();
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    return Stepper(form, 2 * options.stages, options.max_iterations);
  }
};

}  // namespace nonsep
