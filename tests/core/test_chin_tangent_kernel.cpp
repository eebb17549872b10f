// The tangent kernel (chin_tangent_stages.hpp, chin_tangent_kernel_blocks) against the evaluation path: a model
// offering chin_tangent_steps gets bit for bit the states, tangent vectors and evaluation counts of the same model
// stepped by TangentIntegrator::step, for basic and triplet steps, both forms, k = 1 and 2n vectors, 1, 3, 33 and 70
// states, fixed and run-time dimensions, runs cut into calls anywhere (a run resumed from its states, with no cached
// gradient, too); and the host's way of taking runs with the Lyapunov bookkeeping (after_steps) gives the records of
// after_step.
#include <doctest/doctest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/kernel/chin_kernel.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "paper1d/paper1d.hpp"
#include "paper2d/paper2d.hpp"

namespace test_chin_tangent_kernel {

using namespace nonsep;

namespace {

// Adapter A with a tangent kernel: chin_tangent_kernel_blocks<FixedDimension> when `available`, counting the calls.
template <class A, std::size_t FixedDimension>
struct WithTangentKernel : A {
  bool available = true;
  mutable int calls = 0, gradient_calls = 0;
  bool chin_tangent_steps(const ChinTangentStepsCall& call) const {
    if (!available) return false;
    ++(call.steps.steps == 0 ? gradient_calls : calls);
    chin_tangent_kernel_blocks<FixedDimension>(static_cast<const A&>(*this), call);
    return true;
  }
};
using Paper1DModel = sdk::ModelAdapter<Paper1D>;
using Paper2DModel = sdk::ModelAdapter<Paper2D>;
static_assert(ModelWithChinTangentSteps<WithTangentKernel<Paper1DModel, 1>>);
static_assert(!ModelWithChinTangentSteps<Paper1DModel>);

PhaseSpaceBatch spread_states(std::size_t n, std::size_t count) {
  PhaseSpaceBatch x(n, count);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x.q()[i] = 0.4 + 0.7 * static_cast<double>((i * 37) % 101) / 101.0;
    x.p()[i] = -0.3 + 0.5 * static_cast<double>((i * 53) % 97) / 97.0;
  }
  return x;
}

PhaseSpaceBatch spread_vectors(std::size_t n, std::size_t count) {
  PhaseSpaceBatch v(n, count);
  for (std::size_t i = 0; i < v.size(); ++i) {
    v.q()[i] = 1.0 / static_cast<double>(i % 7 + 1);
    v.p()[i] = -0.5 + static_cast<double>((i * 29) % 31) / 31.0;
  }
  return v;
}

bool same_bits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

IntegratorSpec spec_of(const std::string& scheme, HamiltonianForm form) {
  IntegratorSpec spec;
  spec.scheme = scheme;
  spec.form = form;
  if (scheme == "triplet") spec.options = ChinOptions{Fraction(4, 3)};
  return spec;
}

// 11 steps as calls of 4, 1 and 6 steps through the kernel, against 11 calls of step() through the evaluation path;
// then 3 more from a new integrator (a resumed run: its first gradient from the kernel's call of no steps).
template <class A, std::size_t FixedDimension>
void check(const std::string& scheme, HamiltonianForm form, std::size_t count, std::size_t k) {
  const std::string label = scheme + (form == HamiltonianForm::TTV ? " TTV" : " VVT") + ", " + std::to_string(count) +
                            " states, k = " + std::to_string(k) + ", fixed dimension " + std::to_string(FixedDimension);
  CAPTURE(label);
  const A plain{};
  const WithTangentKernel<A, FixedDimension> kernel{};
  const std::size_t n = plain.dimension();
  const double dt = 0.01;
  PhaseSpaceBatch x = spread_states(n, count), y = x;
  PhaseSpaceBatch v = spread_vectors(n, count * k), w = v;
  TangentIntegrator evaluation(spec_of(scheme, form), k), through_kernel(spec_of(scheme, form), k);
  for (int step = 0; step < 11; ++step) evaluation.step(plain, x, v, dt);
  for (const std::uint64_t run : {4, 1, 6}) REQUIRE(through_kernel.step_kernel_n(kernel, y, w, dt, run));
  CHECK(kernel.calls == 3);
  CHECK(kernel.gradient_calls == 1);
  CHECK(same_bits(x.q(), y.q()));
  CHECK(same_bits(x.p(), y.p()));
  CHECK(same_bits(v.q(), w.q()));
  CHECK(same_bits(v.p(), w.p()));
  CHECK(evaluation.evaluations() == through_kernel.evaluations());
  TangentIntegrator resumed(spec_of(scheme, form), k);
  for (int step = 0; step < 3; ++step) evaluation.step(plain, x, v, dt);
  REQUIRE(resumed.step_kernel_n(kernel, y, w, dt, 3));
  CHECK(kernel.gradient_calls == 2);
  CHECK(same_bits(x.q(), y.q()));
  CHECK(same_bits(x.p(), y.p()));
  CHECK(same_bits(v.q(), w.q()));
  CHECK(same_bits(v.p(), w.p()));
}

}  // namespace

TEST_CASE("tangent kernel: states and vectors bit for bit those of the evaluation path") {
  for (const std::string scheme : {"basic", "triplet"})
    for (const HamiltonianForm form : {HamiltonianForm::TTV, HamiltonianForm::VVT})
      for (const std::size_t count : {1, 3, 33, 70}) {
        check<Paper1DModel, 1>(scheme, form, count, 1);
        check<Paper1DModel, 1>(scheme, form, count, 2);
        check<Paper1DModel, 0>(scheme, form, count, 2);
        check<Paper2DModel, 2>(scheme, form, count, 1);
        check<Paper2DModel, 2>(scheme, form, count, 4);
        check<Paper2DModel, 0>(scheme, form, count, 3);
      }
}

TEST_CASE("tangent kernel: a model without one, an expansion, or a model refusing leaves the evaluation path") {
  const Paper1DModel plain{};
  WithTangentKernel<Paper1DModel, 1> refusing{};
  refusing.available = false;
  PhaseSpaceBatch x = spread_states(1, 4), v = spread_vectors(1, 4);
  const PhaseSpaceBatch x0 = x, v0 = v;
  TangentIntegrator basic(spec_of("basic", HamiltonianForm::TTV), 1);
  CHECK_FALSE(basic.step_kernel_n(plain, x, v, 0.01, 5));
  CHECK_FALSE(basic.step_kernel_n(refusing, x, v, 0.01, 5));
  IntegratorSpec mpe = spec_of("mpe", HamiltonianForm::TTV);
  mpe.options = ChinOptions{Fraction(4, 3)};
  const WithTangentKernel<Paper1DModel, 1> kernel{};
  CHECK_FALSE(TangentIntegrator(mpe, 1).step_kernel_n(kernel, x, v, 0.01, 5));
  CHECK(kernel.calls == 0);
  CHECK(same_bits(x.q(), x0.q()));
  CHECK(same_bits(v.p(), v0.p()));
}

TEST_CASE("tangent kernel: after_steps of a run gives the records of after_step step by step") {
  const WithTangentKernel<Paper1DModel, 1> kernel{};
  const std::size_t count = 5;
  PhaseSpaceBatch x = spread_states(1, count), y = x;
  PhaseSpaceBatch v = spread_vectors(1, count * 2), w = v;
  LyapunovExponents exponents(2, 4);
  std::vector<LyapunovRecord> stepped(count), runs(count);
  exponents.start(v, stepped);
  exponents.start(w, runs);
  TangentIntegrator one(spec_of("basic", HamiltonianForm::TTV), 2), many(spec_of("basic", HamiltonianForm::TTV), 2);
  const double dt = 0.013;
  for (int step = 0; step < 11; ++step) {
    REQUIRE(one.step_kernel_n(kernel, x, v, dt, 1));
    exponents.after_step(v, stepped, dt);
  }
  for (std::uint64_t left = 11; left > 0;) {
    const std::uint64_t run = std::min(left, exponents.steps_to_renormalization(runs));
    REQUIRE(many.step_kernel_n(kernel, y, w, dt, run));
    exponents.after_steps(w, runs, dt, run, {});
    left -= run;
  }
  CHECK(stepped == runs);
  CHECK(same_bits(v.q(), w.q()));
  CHECK(same_bits(v.p(), w.p()));
  CHECK(exponents.steps_to_renormalization(runs) == 1);
  CHECK_THROWS_AS(exponents.after_steps(w, runs, dt, 2, {}), InvalidArgument);
}

}  // namespace test_chin_tangent_kernel
