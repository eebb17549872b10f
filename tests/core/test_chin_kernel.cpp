// The stepping kernel (chin_kernel.hpp) against the evaluation path: a model offering chin_steps gets bit for bit
// the numbers and evaluation counts of the same model without it, through every Chin scheme (basic, triplet, mpe of
// 2, 3 and 6 terms), both forms, 1, 2, 3, 5, 33, 35 and 300 states, fixed and run-time dimensions, one step size or one
// per state; a triplet's run of steps is one call (a schedule of sub-steps); and a kernel that fails leaves nothing
// stale.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/kernel/chin_kernel.hpp"
#include "support/models.hpp"

namespace test_chin_kernel {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;
using nonsep::testing::VariableMass2D;

namespace {

// Model M with a kernel: chin_kernel_steps<FixedDimension> of Kernel (M's own arithmetic unless given) when
// `available`, counting the calls that took steps (calls) and those of no steps, which only evaluate the gradient
// the steps start from (gradient_calls). `fail_at_call`: that call with steps (1-based) throws ModelError instead,
// as a plugin's kernel failing partway does.
template <class M, std::size_t FixedDimension, class Kernel = M>
struct WithKernel : M {
  bool available = true;
  int fail_at_call = 0;
  mutable int calls = 0, gradient_calls = 0;
  bool chin_steps(const ChinStepsCall& call) const {
    if (!available) return false;
    if (call.steps == 0)
      ++gradient_calls;
    else if (++calls == fail_at_call)
      throw ModelError("the kernel failed");
    chin_kernel_steps<FixedDimension>(Kernel{}, call);
    return true;
  }
};

// Paper1D whose gradients round as a kernel compiled with fused multiply-adds may: 1 + p^2/2 and q + q^3/3 with one
// rounding of the sum, where the evaluation path rounds the product first.
struct FusedPaper1D : Paper1D {
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = std::fma(0.5 * p[b], p[b], 1.0);
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = std::fma(q[b] * q[b], q[b] / 3.0, q[b]);
  }
};
static_assert(ModelWithChinSteps<WithKernel<Paper1D, 1>>);
static_assert(!ModelWithChinSteps<Paper1D>);

const std::array<HamiltonianForm, 2> forms{HamiltonianForm::TTV, HamiltonianForm::VVT};

PhaseSpaceBatch spread_states(std::size_t n, std::size_t count) {
  PhaseSpaceBatch x(n, count);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x.q()[i] = 0.4 + 0.7 * static_cast<double>((i * 37) % 101) / 101.0;
    x.p()[i] = -0.3 + 0.5 * static_cast<double>((i * 53) % 97) / 97.0;
  }
  return x;
}

// Runs `scheme` of `order` for 2 chunks of 4 steps and 1 chunk of 3 (the host's step_n) with and without the kernel.
template <class M, std::size_t FixedDimension>
void check_scheme(const std::string& scheme, HamiltonianForm form, std::size_t count, Fraction order) {
  CAPTURE(scheme);
  CAPTURE(order.value());
  CAPTURE(static_cast<int>(form));
  CAPTURE(count);
  CAPTURE(FixedDimension);
  const M plain{};
  WithKernel<M, FixedDimension> kernel{};
  IntegratorSpec spec{scheme, ChinOptions{order}};
  spec.form = form;
  Integrator with(spec), without(spec);
  auto x = spread_states(plain.dimension(), count);
  auto y = x;
  for (std::uint64_t steps : {4, 4, 3}) {
    with.step_n(kernel, x, 0.01, steps);
    without.step_n(plain, y, 0.01, steps);
  }
  CHECK(x == y);
  CHECK(with.evaluations() == without.evaluations());
  CHECK(kernel.calls > 0);
}

}  // namespace

TEST_CASE("kernel path: every Chin scheme and form gives the evaluation path's numbers and counts bit for bit") {
  // mpe of 2, 3 and 6 terms: whole expansions in the kernel (chin_expansion_stages.hpp).
  for (const auto& [scheme, order] :
       {std::pair{"basic", Fraction(2, 3)}, std::pair{"triplet", Fraction(4, 3)}, std::pair{"mpe", Fraction(4, 3)},
        std::pair{"mpe", Fraction(2)}, std::pair{"mpe", Fraction(4)}})
    for (const auto form : forms)
      for (std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{5}, std::size_t{33},
                                std::size_t{35}, std::size_t{300}}) {
        // Blocks of 32 states in local arrays; the rest in place (5; 12 of 300) or in registers (1; 2, 3; 1 of 33;
        // 3 of 35).
        check_scheme<Paper1D, 1>(scheme, form, count, order);
        check_scheme<Coupled2D, 2>(scheme, form, count, order);
        check_scheme<Coupled2D, 0>(scheme, form, count, order);  // the dimension known at run time: the caller's arrays
      }
}

TEST_CASE("kernel path: steps started again from their states give the numbers of steps that never stopped") {
  // The kernel rounds differently from the evaluation path (a wider instruction set's fused multiply-adds): a run
  // restarted from its states with a fresh integrator (a resume from a checkpoint) must start from the kernel's
  // gradient, not the evaluation path's, to continue bit for bit.
  for (const auto& scheme_and_order :
       {std::pair{"basic", Fraction(2, 3)}, std::pair{"triplet", Fraction(4, 3)}, std::pair{"mpe", Fraction(4, 3)}})
    for (const auto form : forms) {
      const std::string scheme = scheme_and_order.first;  // not a structured binding: CAPTURE's lambda takes it
      const Fraction order = scheme_and_order.second;
      CAPTURE(scheme);
      CAPTURE(static_cast<int>(form));
      WithKernel<Paper1D, 1, FusedPaper1D> kernel{};
      IntegratorSpec spec{scheme, ChinOptions{order}};
      spec.form = form;
      const auto start = spread_states(1, 300);
      auto whole = start, restarted = start, evaluation_path = start;
      Integrator(spec).step_n(kernel, whole, 0.01, 12);  // VVT leaves the finite numbers soon after
      for (int step = 0; step < 12; ++step) {  // restarted at every step: each step starts from a primed gradient
        Integrator fresh(spec);
        fresh.step_n(kernel, restarted, 0.01, 1);
      }
      CHECK(kernel.gradient_calls == 13);
      Integrator(spec).step_n(Paper1D{}, evaluation_path, 0.01, 12);
      CHECK(restarted == whole);
      CHECK_FALSE(evaluation_path == whole);  // the kernel does round differently: the check above can fail
    }
}

TEST_CASE("kernel path: a run of mpe steps is one kernel call, each step the expansion of MultiProductExpansion") {
  for (int terms : {2, 3, 6})
    for (const auto form : forms) {
      CAPTURE(terms);
      CAPTURE(static_cast<int>(form));
      WithKernel<Coupled2D, 2> kernel{};
      MultiProductExpansion<SeparableBasicStep> with(SeparableBasicStep(ChinBasicStep(form)), terms);
      MultiProductExpansion<ChinBasicStep> term_by_term(ChinBasicStep(form), terms);
      auto x = spread_states(2, 7);
      auto y = x;
      with.step_n(kernel, x, 0.01, 6);
      for (int k = 0; k < 6; ++k) term_by_term.step_term_by_term(Coupled2D{}, y, 0.01);
      CHECK(x == y);
      CHECK(with.evaluations() == term_by_term.evaluations());
      CHECK(kernel.calls == 1);
      // A step after the run starts from the combined point's gradient, evaluated anew, as the evaluation path does.
      with.step(kernel, x, 0.01);
      term_by_term.step_term_by_term(Coupled2D{}, y, 0.01);
      CHECK(x == y);
      CHECK(with.evaluations() == term_by_term.evaluations());
    }
}

TEST_CASE("kernel path: mpe of a model with a separable part steps its terms through the basic steps' kernel") {
  // The expansion's terms compose the exact flows of K and U, which the kernel does not take: no whole expansions,
  // and the numbers of the model without a kernel.
  WithKernel<VariableMass2D, 2> kernel{};
  const VariableMass2D plain{};
  IntegratorSpec spec{"mpe", ChinOptions{Fraction(2)}};
  Integrator with(spec), without(spec);
  auto x = spread_states(2, 3);
  auto y = x;
  with.step_n(kernel, x, 0.01, 5);
  without.step_n(plain, y, 0.01, 5);
  CHECK(x == y);
  CHECK(with.evaluations() == without.evaluations());
  CHECK(kernel.calls == 5 * 3);  // a call per round of the terms: 3 a step
}

TEST_CASE("kernel path: an expansion's call fits only with one step size per term") {
  CHECK(chin_eps_fit(2, 1, 5, 2));
  CHECK(chin_eps_fit(6, 1, 1, 6));
  CHECK_FALSE(chin_eps_fit(1, 1, 5, 2));  // one per term, not one for all
  CHECK_FALSE(chin_eps_fit(5, 1, 5, 2));  // nor one per state
  CHECK_FALSE(chin_eps_fit(2, 2, 5, 2));  // one sub-step only
  CHECK_FALSE(chin_eps_fit(1, 1, 5, 1));  // one term is a basic step: terms 0
  CHECK_FALSE(chin_eps_fit(2, 1, 0, 2));
}

TEST_CASE("kernel path: a run of triplet steps is one kernel call, the schedule of its basic steps") {
  for (int levels : {1, 2}) {
    CAPTURE(levels);
    WithKernel<Paper1D, 1> kernel{};
    TripletComposition<SeparableBasicStep> with(SeparableBasicStep{}, levels), without(SeparableBasicStep{}, levels);
    auto x = spread_states(1, 5);
    auto y = x;
    with.step_n(kernel, x, 0.01, 7);
    for (int k = 0; k < 7; ++k) without.step(Paper1D{}, y, 0.01);
    CHECK(x == y);
    CHECK(with.evaluations() == without.evaluations());
    CHECK(kernel.calls == 1);
  }
}

TEST_CASE("kernel path: a schedule of basic steps gives the steps one by one, with or without a kernel") {
  const std::array<double, 3> schedule{0.02, -0.013, 0.005};
  for (const auto form : forms)
    for (std::size_t count : {std::size_t{1}, std::size_t{3}, std::size_t{40}}) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(count);
      WithKernel<Coupled2D, 2> kernel{};
      ChinBasicStep scheduled(form), scheduled_without_kernel(form), one_by_one(form);
      auto x = spread_states(2, count);
      auto y = x;
      auto z = x;
      scheduled.step_schedule_n(kernel, x, schedule, 4);
      scheduled_without_kernel.step_schedule_n(Coupled2D{}, z, schedule, 4);
      for (int k = 0; k < 4; ++k)
        for (double dt : schedule) one_by_one.step(Coupled2D{}, y, dt);
      CHECK(x == y);
      CHECK(z == y);
      CHECK(scheduled.evaluations() == one_by_one.evaluations());
      CHECK(scheduled_without_kernel.evaluations() == one_by_one.evaluations());
      CHECK(kernel.calls == 1);
    }
}

TEST_CASE("kernel path: a call's step sizes fit its sub-steps and states") {
  CHECK(chin_eps_fit(1, 1, 5));
  CHECK(chin_eps_fit(5, 1, 5));
  CHECK(chin_eps_fit(3, 3, 5));
  CHECK(chin_eps_fit(3, 3, 3));
  CHECK_FALSE(chin_eps_fit(5, 3, 5));
  CHECK_FALSE(chin_eps_fit(1, 3, 5));
  CHECK_FALSE(chin_eps_fit(4, 1, 5));
  CHECK_FALSE(chin_eps_fit(0, 0, 5));
  CHECK_FALSE(chin_eps_fit(0, 1, 0));
}

TEST_CASE("kernel path: states with step sizes of their own get the evaluation path's numbers bit for bit") {
  for (const auto form : forms)
    for (std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{5}, std::size_t{33},
                              std::size_t{35}, std::size_t{300}}) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(count);
      std::vector<double> dt(count);
      for (std::size_t b = 0; b < count; ++b) dt[b] = 0.01 * (1.0 + static_cast<double>(b % 7) / 10.0);
      WithKernel<Paper1D, 1> kernel{};
      ChinBasicStep with(form), without(form);
      auto x = spread_states(1, count);
      auto y = x;
      for (int step = 0; step < 3; ++step) {
        with.step(kernel, x, dt);
        without.step(Paper1D{}, y, dt);
      }
      CHECK(x == y);
      CHECK(with.evaluations() == without.evaluations());
      CHECK(kernel.calls == 3);
    }
}

TEST_CASE("kernel path: a model whose kernel is not at hand is stepped through its evaluations") {
  WithKernel<Paper1D, 1> kernel{};
  kernel.available = false;
  ChinBasicStep with, without;
  auto x = spread_states(1, 5);
  auto y = x;
  with.step_n(kernel, x, 0.01, 5);
  without.step_n(Paper1D{}, y, 0.01, 5);
  CHECK(x == y);
  CHECK(with.evaluations() == without.evaluations());
  CHECK(kernel.calls == 0);
}

TEST_CASE("kernel path: steps a stage observer watches go through the evaluations") {
  WithKernel<Paper1D, 1> kernel{};
  ChinBasicStep with, without;
  auto x = spread_states(1, 3);
  auto y = x;
  int flows = 0;
  with.step(kernel, x, 0.01, [&](const FlowStage&, std::span<const double>, const PhaseSpaceBatch&) { ++flows; });
  without.step(Paper1D{}, y, 0.01);
  CHECK(x == y);
  CHECK(flows == 9);
  CHECK(kernel.calls == 0);
}

TEST_CASE("kernel path: a kernel that fails leaves no stale first-same-as-last gradient behind") {
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    WithKernel<Paper1D, 1> kernel{};
    kernel.fail_at_call = 2;
    ChinBasicStep stepper(form), reference(form);
    auto x = spread_states(1, 5);
    auto y = x;
    stepper.step_n(kernel, x, 0.01, 3);
    reference.step_n(Paper1D{}, y, 0.01, 3);
    const auto before = x;
    CHECK_THROWS_AS(stepper.step_n(kernel, x, 0.01, 3), ModelError);
    x = before;
    stepper.step_n(kernel, x, 0.01, 3);
    reference.step_n(Paper1D{}, y, 0.01, 3);
    CHECK(x == y);
  }
}

}  // namespace test_chin_kernel
