// The Gauss-Legendre iteration of a state does not depend on the other states of its batch: a batch evaluates
// either every state (while most iterate; those that stopped are evaluated again and the results discarded) or
// only the states still iterating (gathered), and a state's iterates, stopping decision, evaluation count and
// failure must come out the same either way. What the host relies on for output independent of --threads and of
// how states are grouped into batches.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "support/models.hpp"

namespace test_gauss_batch_composition {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;

namespace {

// 16 states of paper1d from near the equilibrium (few iterations) to 1.8 (many), and one, (3, 3), whose
// iteration diverges at dt = 0.05 (test_comparators_properties.cpp): the batch mixes states that stop early, late
// and fail, so the whole-batch and the gathered evaluation both run, with stopped and failed states in the batch.
PhaseSpaceBatch spread_of_states() {
  PhaseSpaceBatch x(1, 17);
  for (std::size_t b = 0; b < 16; ++b) {
    x.q()[b] = 0.01 + 0.12 * static_cast<double>(b);
    x.p()[b] = 0.01 + 0.12 * static_cast<double>((b * 7) % 16);
  }
  x.q()[16] = 3.0, x.p()[16] = 3.0;
  return x;
}

PhaseSpaceBatch pick(const PhaseSpaceBatch& x, const std::vector<std::size_t>& states) {
  PhaseSpaceBatch out(x.dimension(), states.size());
  for (std::size_t a = 0; a < states.size(); ++a) {
    std::copy(x.q(states[a]).begin(), x.q(states[a]).end(), out.q(a).begin());
    std::copy(x.p(states[a]).begin(), x.p(states[a]).end(), out.p(a).begin());
  }
  return out;
}

}  // namespace

TEST_CASE("Gauss-Legendre: a state's step is the same alone, in the whole batch and in a reordered part of it") {
  for (const int order : {2, 4, 6}) {
    CAPTURE(order);
    const PhaseSpaceBatch start = spread_of_states();
    const std::size_t count = start.count();
    PhaseSpaceBatch whole = start;
    GaussLegendre gauss(HamiltonianForm::TTV, order);
    const auto failures = gauss.try_step(Paper1D{}, whole, 0.05);
    REQUIRE(failures.size() == 1);
    CHECK(failures[0].state == 16);
    const std::vector<int> iterations(gauss.iterations().begin(), gauss.iterations().end());
    // The states need different numbers of iterations (else only the whole-batch evaluation would run).
    CHECK(*std::min_element(iterations.begin(), iterations.end() - 1) + 3 <
          *std::max_element(iterations.begin(), iterations.end() - 1));

    std::uint64_t evaluations_alone = 0;
    for (std::size_t b = 0; b < count; ++b) {
      CAPTURE(b);
      PhaseSpaceBatch one = pick(start, {b});
      GaussLegendre alone(HamiltonianForm::TTV, order);
      CHECK(alone.try_step(Paper1D{}, one, 0.05).size() == (b == 16 ? 1u : 0u));
      CHECK(one == pick(whole, {b}));
      CHECK(alone.iterations()[0] == iterations[b]);
      evaluations_alone += alone.evaluations().grad_H;
    }
    CHECK(gauss.evaluations().grad_H == evaluations_alone);

    // Every third state, in reverse order, the failing one among them: another batch composition.
    std::vector<std::size_t> part;
    for (std::size_t b = count; b-- > 0;)
      if (b % 3 == 1) part.push_back(b);
    PhaseSpaceBatch reordered = pick(start, part);
    GaussLegendre other(HamiltonianForm::TTV, order);
    const auto part_failures = other.try_step(Paper1D{}, reordered, 0.05);
    REQUIRE(part_failures.size() == 1);
    CHECK(part[part_failures[0].state] == 16);
    CHECK(reordered == pick(whole, part));
    for (std::size_t a = 0; a < part.size(); ++a) CHECK(other.iterations()[a] == iterations[part[a]]);
  }
}

TEST_CASE("Gauss-Legendre: in two dimensions, many steps of a batch equal the states stepped alone") {
  PhaseSpaceBatch batch(2, 9);
  for (std::size_t b = 0; b < 9; ++b) {
    const double r = 0.1 + 0.1 * static_cast<double>(b);
    batch.q(b)[0] = r, batch.q(b)[1] = -0.5 * r, batch.p(b)[0] = 0.3 * r, batch.p(b)[1] = r * r;
  }
  const PhaseSpaceBatch start = batch;
  for (const auto form : {HamiltonianForm::TTV, HamiltonianForm::VVT}) {
    CAPTURE(static_cast<int>(form));
    batch = start;
    GaussLegendre gauss(form, 6);
    for (int s = 0; s < 20; ++s) gauss.step(Coupled2D{}, batch, 0.03);
    for (std::size_t b = 0; b < 9; ++b) {
      PhaseSpaceBatch one = pick(start, {b});
      GaussLegendre alone(form, 6);
      for (int s = 0; s < 20; ++s) alone.step(Coupled2D{}, one, 0.03);
      CHECK(one == pick(batch, {b}));
    }
  }
}

}  // namespace test_gauss_batch_composition
