// Bad parameters are rejected with messages that name the problem and what is allowed.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>

#include "nonsep/core.hpp"
#include "support/models.hpp"

namespace test_core_errors {

using namespace nonsep;

namespace {
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no error)";
}
bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
}  // namespace

TEST_CASE("a message shows a number as the shortest text that reads back as it") {
  CHECK(found_number(2.5) == "2.5");
  CHECK(found_number(0.1) == "0.1");
  CHECK(found_number(1e-8) == "1e-08");  // std::to_string: 0.000000
  CHECK(found_number(-0.0) == "-0");
  CHECK(found_number(std::numeric_limits<double>::infinity()) == "inf");
}

TEST_CASE("t2 = 0 and non-finite t2 are rejected") {
  CHECK(contains(error_of([] { ChinBasicStep(HamiltonianForm::TTV, 0.0); }), "t2 must be a finite non-zero number"));
  CHECK(error_of([] { ChinCoefficients::from_t2(0.0); }).ends_with("(found 0)"));  // not 0.000000
  CHECK(error_of([] { ChinCoefficients::from_t2(std::nan("")); }).ends_with("(found nan)"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(4, 3), std::nan("")}});
                 }),
                 "t2"));
}

TEST_CASE("non-finite or zero dt is rejected before anything moves") {
  ChinBasicStep basic;
  const double q[] = {1.0}, p[] = {0.0};
  auto x = PhaseSpaceBatch::single(q, p);
  const auto before = x;
  for (double dt : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 0.0}) {
    CAPTURE(dt);
    CHECK(contains(error_of([&] { basic.step(nonsep::testing::Paper1D{}, x, dt); }), "step size dt must be finite"));
    CHECK(x == before);
  }
  Integrator mpe(IntegratorSpec{"mpe", ChinOptions{Fraction(2)}});
  CHECK(contains(error_of([&] { mpe.step(nonsep::testing::Paper1D{}, x, -std::numeric_limits<double>::infinity()); }),
                 "dt"));
}

TEST_CASE("orders that do not exist are rejected with the list of those that do") {
  const auto message = error_of([] { Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(1)}}); });
  CHECK(contains(message, "the orders of triplet are "));
  CHECK(message.ends_with(" (found 1)"));
  CHECK(contains(message, "2/3, 4/3, 2, 8/3, 10/3, 4"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(5, 3)}});
                 }),
                 "the orders of mpe are 2/3, 4/3"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(-2, 3)}});
                 }),
                 "the orders of mpe are"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"basic", ChinOptions{Fraction(4, 3)}});
                 }),
                 "the highest order of basic is 2/3 (found 4/3)"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(40)}});
                 }),
                 "the highest order of mpe is"));
  CHECK(contains(error_of([] { Integrator(IntegratorSpec{"leapfrog"}); }), "unknown integrator scheme 'leapfrog'"));
  // Orders near the int64 limit (found by fuzzing: 3a overflowed) are refused, not computed with.
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(6148914691236517204)}});
                 }),
                 "the highest order of mpe is"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(9223372036854775806, 3)}});
                 }),
                 "the highest order of triplet is"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(9223372036854775807)}});
                 }),
                 "the orders of triplet are"));
  CHECK(contains(error_of([] {
                   Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(-9223372036854775807, 3)}});
                 }),
                 "the orders of triplet are"));
  // Every valid order up to the limits is accepted and reported back exactly.
  for (int j = 1; j <= 8; ++j) {
    CHECK(Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(2 * j, 3)}}).describe().order ==
          Fraction(2 * j, 3));
    CHECK(Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(2 * j, 3)}}).describe().order == Fraction(2 * j, 3));
  }
}

TEST_CASE("exact fractions parse strictly") {
  CHECK(Fraction::parse("4/3") == Fraction(4, 3));
  CHECK(Fraction::parse(" 8 / 3 ") == Fraction(8, 3));
  CHECK(Fraction::parse("6/3") == Fraction(2));
  CHECK(Fraction::parse("2").to_string() == "2");
  CHECK(Fraction(10, 3).to_string() == "10/3");
  for (const char* bad : {"", "4/", "/3", "1.5", "4/0", "four", "4/3/2", "4//3"}) {
    CAPTURE(bad);
    CHECK(contains(error_of([&] { Fraction::parse(bad); }), "is not an exact fraction"));
  }
  // The lowest int64 has no negation: refused rather than overflowed.
  CHECK(contains(error_of([] { Fraction::parse("-9223372036854775808/-1"); }), "within +-(2^63 - 1)"));
  CHECK(contains(error_of([] { Fraction(1, std::numeric_limits<std::int64_t>::min()); }), "within +-(2^63 - 1)"));
  CHECK(Fraction::parse("-9223372036854775807/9223372036854775807") == Fraction(-1));
  // A batch whose dimension differs from the model's is refused.
  PhaseSpaceBatch wrong(2, 1);
  ChinBasicStep basic;
  CHECK(contains(error_of([&] { basic.step(nonsep::testing::Paper1D{}, wrong, 0.1); }),
                 "the model has dimension 1 but the states have dimension 2"));
}

TEST_CASE("integrators describe themselves") {
  const auto basic = Integrator(IntegratorSpec{"basic"}).describe();
  CHECK(basic.order.to_string() == "2/3");
  CHECK(basic.symplectic);
  CHECK(basic.time_reversible);
  CHECK(basic.basic_steps_per_step == 1);
  const auto triplet = Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(8, 3), -2.0}}).describe();
  CHECK(triplet.scheme == "triplet");
  CHECK(triplet.basic_steps_per_step == 27);
  CHECK(triplet.t2 == -2.0);
  const auto mpe = Integrator(IntegratorSpec{"mpe", ChinOptions{Fraction(4)}}).describe();
  CHECK_FALSE(mpe.symplectic);
  CHECK_FALSE(mpe.time_reversible);
  CHECK(mpe.basic_steps_per_step == 21);
  // The catalogue lists every scheme with its parameters and defaults, for the host's reader and help text.
  // Chin's three first, then the three comparators.
  REQUIRE(scheme_catalogue().size() == 6);
  const char* comparators[] = {"tao", "implicit_midpoint", "gauss"};
  for (std::size_t i = 0; i < 3; ++i) {
    CAPTURE(comparators[i]);
    CHECK(scheme_catalogue()[3 + i].name == comparators[i]);
    CHECK(scheme_catalogue()[3 + i].family == "comparator");
    CHECK(scheme_catalogue()[3 + i].summary.find("Needs the plugin's Hessians and third derivatives") !=
          std::string::npos);
  }
  for (const auto& scheme : scheme_catalogue().first(3)) {
    CAPTURE(scheme.name);
    CHECK(scheme.family == "chin");
    CHECK(!scheme.summary.empty());
    CHECK(!scheme.equations.empty());
    REQUIRE(scheme.parameters.size() == 2);
    CHECK(scheme.parameters[1].name == "t2");
    CHECK(std::stod(scheme.parameters[1].default_text) == ChinCoefficients::default_t2());
  }
  CHECK_FALSE(find_scheme("mpe")->symplectic);
  CHECK(find_scheme("rk4") == nullptr);
}

TEST_CASE("each catalogue entry builds exactly its orders, with its own flags") {
  for (const auto& scheme : scheme_catalogue()) {
    CAPTURE(scheme.name);
    const bool chin = scheme.family == "chin";
    CHECK((chin || scheme.family == "comparator"));
    const auto orders = scheme.orders();
    REQUIRE(orders.size() ==
            (chin ? static_cast<std::size_t>(scheme.highest_order_index) : scheme.comparator_orders.size()));
    // A comparator's order is its "order" option (tao) or twice its stages (gauss); implicit_midpoint has only 2.
    const auto spec_of = [&](const Fraction& order) {
      IntegratorSpec spec = default_spec(scheme);
      for (const auto& parameter : scheme.parameters) {
        if (parameter.name == "order") set_option(spec, parameter, order);
        if (parameter.name == "t2") set_option(spec, parameter, -2.0);
        if (parameter.name == "stages") set_option(spec, parameter, static_cast<double>(order.numerator()) / 2.0);
      }
      return spec;
    };
    for (const Fraction& order : orders) {
      CAPTURE(order.to_string());
      const Integrator integrator(spec_of(order));
      const auto description = Integrator::describe(spec_of(order));
      // Described without building a stepper, it is what the stepper built says of itself.
      IntegratorDescription built = std::visit([](const auto& s) { return description_of(s); }, integrator.stepper());
      built.scheme = scheme.name;  // gauss's stepper serves implicit_midpoint too
      CHECK(description == built);
      CHECK(integrator.describe() == description);
      CHECK(Integrator::describe(spec_of_order(scheme, order)).order == order);
      CHECK(description.scheme == scheme.name);
      CHECK(description.family == scheme.family);
      CHECK(description.order == order);
      CHECK(description.symplectic == scheme.symplectic);
      CHECK(description.time_reversible == scheme.time_reversible);
      CHECK(description.t2 == (chin ? -2.0 : 0.0));
    }
    // The orders scheme "auto" tries are among the scheme's.
    for (const Fraction& order : scheme.auto_orders)
      CHECK(std::find(orders.begin(), orders.end(), order) != orders.end());
    const Fraction absent(orders.back().numerator() + 1, orders.back().denominator());
    CHECK(contains(error_of([&] { spec_of_order(scheme, absent); }), "the scheme '" + scheme.name + "' has no order " +
                                                                         absent.to_string() + "; its orders are " +
                                                                         orders.front().to_string()));
    if (chin) {
      // The next order of the family is beyond the entry's list, and the default order is one of its orders.
      const Fraction beyond(2 * (scheme.highest_order_index + 1), 3);
      CHECK(contains(error_of([&] {
                       Integrator(IntegratorSpec{scheme.name, ChinOptions{beyond}});
                     }),
                     "the highest order of " + scheme.name + " is"));
      CHECK(error_of([&] {
              Integrator::describe(IntegratorSpec{scheme.name, ChinOptions{beyond}});
            }) == error_of([&] {
              Integrator(IntegratorSpec{scheme.name, ChinOptions{beyond}});
            }));
      // t2 is refused before the order, described or built.
      CHECK(error_of([&] {
              Integrator::describe(IntegratorSpec{scheme.name, ChinOptions{beyond, 0.0}});
            }) == error_of([&] {
              Integrator(IntegratorSpec{scheme.name, ChinOptions{beyond, 0.0}});
            }));
      CHECK(contains(error_of([&] {
                       Integrator::describe(IntegratorSpec{scheme.name, ChinOptions{beyond, 0.0}});
                     }),
                     "t2"));
      CHECK(std::find(orders.begin(), orders.end(), Fraction::parse(scheme.parameters[0].default_text)) !=
            orders.end());
    } else if (scheme.name != "implicit_midpoint") {
      // The order after the last (tao 8, gauss 9 stages) does not exist: the message names the valid ones.
      const Fraction beyond(orders.back().numerator() + 2);
      CHECK(contains(error_of([&] { Integrator(spec_of(beyond)); }), scheme.name == "tao" ? "2, 4" : "1 to 8"));
      CHECK(error_of([&] { Integrator::describe(spec_of(beyond)); }) == error_of([&] { Integrator(spec_of(beyond)); }));
    }
  }
}

TEST_CASE("comparator options: each bad value has its own message") {
  IntegratorSpec tao{"tao", TaoOptions{Fraction(4, 3)}};
  CHECK(contains(error_of([&] { Integrator{tao}; }), "orders 2, 4 and 6 (found 4/3)"));
  tao.options = TaoOptions{Fraction(2), 0.0};
  CHECK(contains(error_of([&] { Integrator{tao}; }), "omega must be finite and positive; the default is 20 (found 0)"));
  // An integer option refuses a number that is not whole when it is set by its catalogue name (the job reader).
  IntegratorSpec gauss{"gauss"};
  const ParameterDescription& stages = find_scheme("gauss")->parameters[0];
  CHECK(contains(error_of([&] { set_option(gauss, stages, 1.5); }), "stages must be a whole number (found 1.5)"));
  set_option(gauss, stages, 0.0);
  CHECK(contains(error_of([&] { Integrator{gauss}; }), "1 to 8 stages, orders 2 to 16 (found 0)"));
  gauss.options = GaussOptions{2, 0};
  CHECK(contains(error_of([&] { Integrator{gauss}; }), "max_iterations >= 1"));
  CHECK(contains(error_of([&] { Integrator::describe(gauss); }), "max_iterations >= 1"));
  CHECK(contains(error_of([&] {
                   Integrator::describe(IntegratorSpec{"implicit_midpoint", ImplicitMidpointOptions{0}});
                 }),
                 "max_iterations >= 1"));
  CHECK(contains(error_of([&] { Integrator::describe(tao); }), "omega must be finite and positive"));
  CHECK(contains(error_of([&] { Integrator::describe(IntegratorSpec{"rk4"}); }), "unknown integrator scheme 'rk4'"));
  // A comparator has no t2: its options have no member for it (a programming error, not a job's).
  IntegratorSpec midpoint{"implicit_midpoint"};
  CHECK_THROWS_AS(set_option(midpoint, find_scheme("basic")->parameters[1], 0.0), std::logic_error);
  CHECK_NOTHROW(Integrator{midpoint});
  // A model type without Hessians and third derivatives: the comparator refuses to step, a Chin scheme steps.
  struct GradientsOnly {
    std::size_t dimension() const { return 1; }
    void grad_T(std::span<const double> p, std::span<double> out, std::size_t) const { out[0] = p[0]; }
    void grad_V(std::span<const double> q, std::span<double> out, std::size_t) const { out[0] = q[0]; }
  };
  const double q[] = {1.0}, p[] = {0.5};
  auto x = PhaseSpaceBatch::single(q, p);
  Integrator comparator(IntegratorSpec{"tao", TaoOptions{Fraction(2)}});
  CHECK(contains(error_of([&] { comparator.step(GradientsOnly{}, x, 0.1); }), "needs a model with Hessians"));
  Integrator basic(IntegratorSpec{"basic"});
  CHECK_NOTHROW(basic.step(GradientsOnly{}, x, 0.1));
  // A comparator's tangent map needs the directional derivative of grad H: a model without it is refused, naming it.
  for (const IntegratorSpec& spec : {IntegratorSpec{"tao", TaoOptions{Fraction(2)}}, IntegratorSpec{"gauss"}}) {
    TangentIntegrator tangent(spec);
    auto tangents = PhaseSpaceBatch::single(q, p);
    CHECK(contains(error_of([&] { tangent.step(testing::Paper1D{}, x, tangents, 0.1); }),
                   "needs a model with third derivatives and the directional derivative of grad H (the plugin entry "
                   "hvp_H"));
  }
}

namespace {
template <class Base>
constexpr bool mpe_accepts = requires {
  typename MultiProductExpansion<Base>;
};
}  // namespace

// A base stepper MultiProductExpansion cannot drive is refused at compile time by the concept its template names
// (multi_product_expansion.hpp): the basic step has a step with one size per state, the triplet composition not.
static_assert(StepperWithPerStateStepSizes<ChinBasicStep>);
static_assert(!StepperWithPerStateStepSizes<TripletComposition<>>);
static_assert(mpe_accepts<ChinBasicStep>);
static_assert(!mpe_accepts<TripletComposition<>>);

TEST_CASE("an option's declared range is what its scheme accepts, at both ends") {
  // The catalogue states each option's range (the job schema prints it); the scheme's own check decides. They agree:
  // the bounds are accepted (an exclusive one is refused), and the nearest values outside them are refused.
  int ranges = 0;
  for (const auto& scheme : scheme_catalogue())
    for (const auto& parameter : scheme.parameters) {
      if (!std::isfinite(parameter.minimum) && !std::isfinite(parameter.maximum)) continue;
      CAPTURE(scheme.name);
      CAPTURE(parameter.name);
      ++ranges;
      const auto accepts = [&](double value) {
        IntegratorSpec spec = default_spec(scheme);
        set_option(spec, parameter, value);
        try {
          Integrator::describe(spec);
          Integrator built(spec);
          return true;
        } catch (const InvalidArgument&) {
          return false;
        }
      };
      const double step = parameter.integer ? 1.0 : 1e-9;
      if (std::isfinite(parameter.minimum)) {
        CHECK(accepts(parameter.minimum) != parameter.minimum_exclusive);
        CHECK_FALSE(accepts(parameter.minimum - step));
        if (parameter.minimum_exclusive) CHECK(accepts(parameter.minimum + step));
      }
      if (std::isfinite(parameter.maximum)) {
        CHECK(accepts(parameter.maximum));
        CHECK_FALSE(accepts(parameter.maximum + step));
      }
    }
  CHECK(ranges == 4);  // tao omega > 0; implicit_midpoint and gauss max_iterations >= 1; gauss stages 1 to 8
}

}  // namespace test_core_errors
