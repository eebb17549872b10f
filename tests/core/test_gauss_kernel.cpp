// The Gauss-Legendre stepping kernel (gauss_stages.hpp, gauss_kernel_steps) against the evaluation path: a model
// offering gauss_steps gets bit for bit the states, iterations, evaluation counts, stage points and private state
// (the memory a checkpoint keeps) of the same model without it, for 1 to 8 stages, both product forms and a model
// given by H, fixed and run-time dimensions, batches of 1 to 70 states (across the kernel's blocks of 32), with and
// without starting values, over runs of steps and a changed dt; and a step the kernel cannot finish (a state whose
// iteration fails) is taken again through the evaluations, with the same failures and nothing stale.
#include <doctest/doctest.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "henon_heiles/henon_heiles.hpp"
#include "nonsep/core/kernel/gauss_stages.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/sdk/hamiltonian_adapter.hpp"
#include "support/models.hpp"

namespace test_gauss_kernel {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;

namespace {

// Model M with a kernel: gauss_kernel_steps<FixedDimension> of M when `available`, counting its calls.
template <class M, std::size_t FixedDimension>
struct WithGaussKernel : M {
  bool available = true;
  mutable int calls = 0;
  bool gauss_steps(const GaussStepsCall& call) const {
    if (!available) return false;
    ++calls;
    gauss_kernel_steps<FixedDimension>(static_cast<const M&>(*this), call);
    return true;
  }
};
static_assert(ModelWithGaussSteps<WithGaussKernel<Paper1D, 1>> && !ModelWithGaussSteps<Paper1D>);

// `count` states of dimension n spread over a region where the iteration converges at dt = 0.01 in a few to
// many iterations.
PhaseSpaceBatch spread(std::size_t n, std::size_t count) {
  PhaseSpaceBatch x(n, count);
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t k = 0; k < n; ++k) {
      x.q(b)[k] = 0.05 + 0.9 * static_cast<double>((b * 7 + k * 3) % 23) / 23.0;
      x.p(b)[k] = -0.4 + 0.8 * static_cast<double>((b * 5 + k) % 19) / 19.0;
    }
  return x;
}

bool same_bits(std::span<const double> a, std::span<const double> b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](double x, double y) {
           return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
         });
}

// Runs `steps` steps of dt (and as many of dt2 after) with the kernel and through the evaluations; checks every
// step's numbers are the same, and that the kernel took every step.
template <class Kernel, class Plain>
void check_same_run(const Kernel& kernel_model, const Plain& plain_model, HamiltonianForm form, int order,
                    PhaseSpaceBatch start, int steps, bool extrapolate = true) {
  GaussLegendre with(form, order, GaussLegendre::default_max_iterations, extrapolate);
  GaussLegendre without(form, order, GaussLegendre::default_max_iterations, extrapolate);
  PhaseSpaceBatch a = start, b = start;
  const int calls_before = kernel_model.calls;
  for (int step = 0; step < 2 * steps; ++step) {
    CAPTURE(step);
    const double dt = step < steps ? 0.01 : -0.0125;
    REQUIRE(with.try_step(kernel_model, a, dt).empty());
    REQUIRE(without.try_step(plain_model, b, dt).empty());
    REQUIRE(same_bits(a.q(), b.q()));
    REQUIRE(same_bits(a.p(), b.p()));
    REQUIRE(std::equal(with.iterations().begin(), with.iterations().end(), without.iterations().begin(),
                       without.iterations().end()));
    REQUIRE(same_bits(with.stage_points_q(), without.stage_points_q()));
    REQUIRE(same_bits(with.stage_points_p(), without.stage_points_p()));
  }
  CHECK(with.evaluations().grad_H == without.evaluations().grad_H);
  CHECK(same_bits(with.save_state(a).columns[0].values, without.save_state(b).columns[0].values));
  CHECK(kernel_model.calls - calls_before == 2 * steps);
}

}  // namespace

TEST_CASE("Gauss kernel: bit for bit the evaluation path, 1 to 8 stages, both forms, fixed and run-time dimensions") {
  for (const int stages : {1, 2, 3, 4, 5, 8}) {
    CAPTURE(stages);
    for (const std::size_t count : {std::size_t{1}, std::size_t{5}, std::size_t{33}, std::size_t{70}}) {
      CAPTURE(count);
      const WithGaussKernel<Paper1D, 1> fixed;
      const WithGaussKernel<Paper1D, 0> run_time;
      check_same_run(fixed, Paper1D{}, HamiltonianForm::TTV, 2 * stages, spread(1, count), 6);
      check_same_run(run_time, Paper1D{}, HamiltonianForm::TTV, 2 * stages, spread(1, count), 6);
      const WithGaussKernel<Coupled2D, 2> coupled;
      for (const HamiltonianForm form : {HamiltonianForm::TTV, HamiltonianForm::VVT})
        check_same_run(coupled, Coupled2D{}, form, 2 * stages, spread(2, count), 4);
    }
  }
}

TEST_CASE("Gauss kernel: bit for bit the evaluation path without starting values, and for a model given by H") {
  const WithGaussKernel<Coupled2D, 0> coupled;
  check_same_run(coupled, Coupled2D{}, HamiltonianForm::TTV, 6, spread(2, 40), 5, false);
  using Henon = sdk::HamiltonianAdapter<HenonHeiles>;
  const WithGaussKernel<Henon, 0> henon;
  for (const int order : {2, 6, 12}) {
    CAPTURE(order);
    check_same_run(henon, Henon{}, HamiltonianForm::TTV, order, spread(2, 37), 5);
  }
}

TEST_CASE("Gauss kernel: a step it cannot finish is taken through the evaluations, with the same failures") {
  // paper1d's state (3, 3) diverges at dt = 0.05 (test_gauss_batch_composition.cpp); with max_iterations 4 the
  // states far from the equilibrium do not converge either.
  for (const int max_iterations : {4, 100}) {
    CAPTURE(max_iterations);
    PhaseSpaceBatch start = spread(1, 40);
    start.q(17)[0] = 3.0;
    start.p(17)[0] = 3.0;
    const WithGaussKernel<Paper1D, 1> kernel_model;
    GaussLegendre with(HamiltonianForm::TTV, 6, max_iterations), without(HamiltonianForm::TTV, 6, max_iterations);
    PhaseSpaceBatch a = start, b = start;
    for (int step = 0; step < 3; ++step) {
      CAPTURE(step);
      const auto failed_with = with.try_step(kernel_model, a, 0.05);
      const auto failed_without = without.try_step(Paper1D{}, b, 0.05);
      REQUIRE(!failed_with.empty());
      REQUIRE(failed_with.size() == failed_without.size());
      for (std::size_t i = 0; i < failed_with.size(); ++i) {
        CHECK(failed_with[i].state == failed_without[i].state);
        CHECK(failed_with[i].reason == failed_without[i].reason);
      }
      REQUIRE(same_bits(a.q(), b.q()));
      REQUIRE(same_bits(a.p(), b.p()));
      CHECK(same_bits(with.save_state(a).columns[0].values, without.save_state(b).columns[0].values));
    }
    CHECK(kernel_model.calls == 3);
    CHECK(with.evaluations().grad_H == without.evaluations().grad_H);
  }
}

TEST_CASE("Gauss kernel: a model whose kernel is not at hand is stepped through the evaluations") {
  WithGaussKernel<Paper1D, 1> off;
  off.available = false;
  GaussLegendre with(HamiltonianForm::TTV, 6), without(HamiltonianForm::TTV, 6);
  PhaseSpaceBatch a = spread(1, 9), b = a;
  for (int step = 0; step < 4; ++step) {
    REQUIRE(with.try_step(off, a, 0.01).empty());
    REQUIRE(without.try_step(Paper1D{}, b, 0.01).empty());
  }
  CHECK(a == b);
  CHECK(off.calls == 0);
}

}  // namespace test_gauss_kernel
