// A scheme added the way a shipped one is (stepper.hpp): a stepper, its options, its scheme type with its
// description, its tangent map through tangent_map_of, and the shipped list extended by it. The integrator steps it,
// the catalogue describes it, the job reader's option calls set it by name and the tangent integrator maps its
// vectors; nothing of the core names it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "support/models.hpp"
#include "support/phase_space_jacobian.hpp"

namespace nonsep::extension_test {

// The basic step taken `substeps` times with dt / substeps: order 2/3, as the basic step.
class RepeatedBasicStep {
 public:
  RepeatedBasicStep(SeparableBasicStep base, int substeps) : base_(std::move(base)), substeps_(substeps) {}
  const SeparableBasicStep& base() const { return base_; }
  int substeps() const { return substeps_; }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  IntegratorDescription describe() const { return description(base_.describe(), substeps_); }
  static IntegratorDescription description(IntegratorDescription base, int substeps) {
    base.scheme = "repeated";
    base.basic_steps_per_step = static_cast<std::uint64_t>(substeps);
    return base;
  }
  template <Model M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    for (int s = 0; s < substeps_; ++s) base_.step(model, x, dt / substeps_);
  }

 private:
  SeparableBasicStep base_;
  int substeps_;
};

struct RepeatedOptions {
  int substeps = 2;
  double t2 = ChinCoefficients::default_t2();
  static constexpr auto members() {
    return std::tuple{option("substeps", &RepeatedOptions::substeps, "basic steps per step, an integer >= 1"),
                      option("t2", &RepeatedOptions::t2, "free coefficient of the basic step", true)};
  }
};

struct RepeatedScheme {
  using Options = RepeatedOptions;
  using Stepper = RepeatedBasicStep;
  static SchemeDescription description() {
    return {.name = "repeated",
            .method = "The basic step repeated",
            .equations = "eq. (expalg)",
            .summary = "substeps basic steps of dt / substeps.",
            .family = "chin",
            .symplectic = true,
            .time_reversible = true,
            .parameters = describe_options(RepeatedOptions{}),
            .highest_order_index = 1,
            .comparator_orders = {},
            .auto_orders = {}};
  }
  static IntegratorDescription describe(const Options& options) {
    const IntegratorDescription base = ChinBasicStep::description(ChinCoefficients::from_t2(options.t2).t2);
    if (options.substeps < 1)
      throw InvalidArgument("repeated needs substeps >= 1 (found " + std::to_string(options.substeps) + ")");
    return Stepper::description(base, options.substeps);
  }
  static Stepper make(const Options& options, HamiltonianForm form) {
    describe(options);
    return Stepper(SeparableBasicStep(ChinBasicStep(form, options.t2)), options.substeps);
  }
};

// Its tangent map, beside it as a shipped scheme's is beside its tangent stepper.
class TangentRepeatedBasicStep {
 public:
  explicit TangentRepeatedBasicStep(const RepeatedBasicStep& stepper)
      : base_(stepper.base()), substeps_(stepper.substeps()) {}
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  const HessianCounts& hessian_evaluations() const { return base_.hessian_evaluations(); }
  template <ModelWithHessians M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    for (int s = 0; s < substeps_; ++s) base_.step(model, x, tangents, dt / substeps_);
  }

 private:
  TangentSeparableComposition base_;
  int substeps_;
};
inline TangentRepeatedBasicStep tangent_map_of(const RepeatedBasicStep& stepper, std::size_t) {
  return TangentRepeatedBasicStep(stepper);
}

using ExtendedIntegrator = WithShippedSchemes<BasicIntegrator, RepeatedScheme>;
using ExtendedSpec = WithShippedSchemes<BasicIntegratorSpec, RepeatedScheme>;
using ExtendedTangentIntegrator = WithShippedSchemes<BasicTangentIntegrator, RepeatedScheme>;

bool same(const PhaseSpaceBatch& a, const PhaseSpaceBatch& b) {
  return std::ranges::equal(a.q(), b.q()) && std::ranges::equal(a.p(), b.p());
}

const ParameterDescription& parameter(const std::string& name) {
  const auto catalogue = ExtendedIntegrator::catalogue();
  const auto& parameters = catalogue.back().parameters;
  return *std::find_if(parameters.begin(), parameters.end(), [&](const auto& p) { return p.name == name; });
}

}  // namespace nonsep::extension_test

using namespace nonsep;
using namespace nonsep::extension_test;

TEST_CASE("an added scheme: the catalogue lists it after the shipped ones, with its options") {
  const auto catalogue = ExtendedIntegrator::catalogue();
  REQUIRE(catalogue.size() == scheme_catalogue().size() + 1);
  for (std::size_t i = 0; i < scheme_catalogue().size(); ++i) CHECK(catalogue[i].name == scheme_catalogue()[i].name);
  CHECK(catalogue.back().name == "repeated");
  REQUIRE(catalogue.back().parameters.size() == 2);
  CHECK(catalogue.back().parameters[0].name == "substeps");
  CHECK(catalogue.back().orders() == std::vector<Fraction>{Fraction(2, 3)});
}

TEST_CASE("an added scheme: its options are set and read by their catalogue names, an integer as an integer") {
  ExtendedSpec spec{"repeated"};
  for (const auto& p : ExtendedIntegrator::catalogue().back().parameters) set_option(spec, p, default_option_value(p));
  CHECK(std::get<RepeatedOptions>(spec.options).substeps == 2);
  CHECK(std::get<RepeatedOptions>(spec.options).t2 == ChinCoefficients::default_t2());
  set_option(spec, parameter("substeps"), 3.0);
  CHECK(std::get<RepeatedOptions>(spec.options).substeps == 3);
  CHECK(std::get<double>(option_value(spec, parameter("substeps"))) == 3.0);
  CHECK_THROWS_WITH_AS(set_option(spec, parameter("substeps"), 2.5), "substeps must be a whole number (found 2.5)",
                       InvalidArgument);
  CHECK_THROWS_AS(set_option(spec, ExtendedIntegrator::catalogue()[0].parameters[0], Fraction(2, 3)),
                  std::logic_error);  // "order": not an option of this scheme
  spec.options = RepeatedOptions{0};
  CHECK_THROWS_WITH_AS(ExtendedIntegrator{spec}, "repeated needs substeps >= 1 (found 0)", InvalidArgument);
}

TEST_CASE("an added scheme steps through the integrator bit for bit as its stepper, and describes itself") {
  const testing::Paper2D model;
  const ExtendedSpec spec{"repeated", RepeatedOptions{3, -2.0}};
  ExtendedIntegrator integrator(spec);
  const auto start = PhaseSpaceBatch::single(std::vector{-0.75, 0.3}, std::vector{-1.5, 0.2});
  auto x = start, by_hand = start;
  integrator.step(model, x, 0.01);
  integrator.step_n(model, x, 0.01, 4);
  SeparableBasicStep basic(ChinBasicStep(HamiltonianForm::TTV, -2.0));
  for (int s = 0; s < 15; ++s) basic.step(model, by_hand, 0.01 / 3);
  CHECK(same(x, by_hand));
  CHECK_FALSE(same(x, start));
  CHECK(integrator.evaluations().grad_T == basic.evaluations().grad_T);

  const IntegratorDescription d = integrator.describe();
  CHECK(d == ExtendedIntegrator::describe(spec));  // what it is, without building it
  CHECK(d.scheme == "repeated");
  CHECK(d.order == Fraction(2, 3));
  CHECK(d.basic_steps_per_step == 3);
  CHECK(d.t2 == -2.0);
  CHECK_FALSE(integrator.is_comparator());
  CHECK(integrator.save_state(x).columns.empty());

  // The shipped schemes in the extended list step as the shipped integrator steps them.
  const ExtendedSpec triplet{"triplet", ChinOptions{Fraction(2)}};
  auto extended = start, shipped = start;
  ExtendedIntegrator(triplet).step(model, extended, 0.01);
  Integrator(IntegratorSpec{"triplet", ChinOptions{Fraction(2)}}).step(model, shipped, 0.01);
  CHECK(same(extended, shipped));
}

TEST_CASE("an added scheme's tangent map: the states as the integrator steps them, the vectors as its base maps them") {
  const testing::Paper2D model;
  const ExtendedSpec spec{"repeated", RepeatedOptions{3, -2.0}};
  CHECK(has_tangent_map(spec));
  ExtendedTangentIntegrator tangent(spec);
  const auto start = PhaseSpaceBatch::single(std::vector{-0.75, 0.3}, std::vector{-1.5, 0.2});
  auto x = start, plain = start, by_hand = start;
  auto vectors = testing::identity_tangents(2), hand_vectors = vectors;
  tangent.step(model, x, vectors, 0.01);
  ExtendedIntegrator(spec).step(model, plain, 0.01);
  TangentSeparableComposition base(SeparableBasicStep(ChinBasicStep(HamiltonianForm::TTV, -2.0)));
  for (int s = 0; s < 3; ++s) base.step(model, by_hand, hand_vectors, 0.01 / 3);
  CHECK(same(x, plain));
  CHECK(same(vectors, hand_vectors));
  CHECK_FALSE(same(vectors, testing::identity_tangents(2)));
  CHECK(tangent.hessian_evaluations().hessian_T == base.hessian_evaluations().hessian_T);
}

namespace nonsep::extension_test {

// Each option of scheme S as the catalogue's default text gives it is the option of scheme_defaults<S>().
template <class S>
void check_catalogue_defaults() {
  const SchemeDescription description = S::description();
  CAPTURE(description.name);
  const typename S::Options defaults = scheme_defaults<S>();
  for (const ParameterDescription& parameter : description.parameters) {
    CAPTURE(parameter.name);
    CHECK(!parameter.default_text.empty());
    CHECK(default_option_value(parameter) == read_option(defaults, parameter.name));
  }
}
template <class... S>
struct CatalogueDefaults {
  static void check() { (check_catalogue_defaults<S>(), ...); }
};

}  // namespace nonsep::extension_test

TEST_CASE(
    "every scheme's catalogue defaults are its options' defaults, written once, and a spec without options has them") {
  WithShippedSchemes<CatalogueDefaults, RepeatedScheme>::check();
  // The compositions share ChinOptions with the basic step and default to order 4/3 (their defaults()).
  for (const char* scheme : {"triplet", "mpe"}) {
    CAPTURE(scheme);
    const IntegratorSpec spec{scheme};
    const auto& entry = *std::find_if(scheme_catalogue().begin(), scheme_catalogue().end(),
                                      [&](const auto& e) { return e.name == scheme; });
    CHECK(std::get<Fraction>(option_value(spec, entry.parameters[0])) == Fraction(4, 3));
    CHECK(Integrator(spec).describe().order == Fraction(4, 3));
  }
  CHECK(std::get<Fraction>(option_value(IntegratorSpec{"basic"}, scheme_catalogue()[0].parameters[0])) ==
        Fraction(2, 3));
}
