// Structural properties of the comparator schemes: symplecticity of every catalogue scheme (one-step Jacobian;
// Tao's on the extended phase space), time reversibility, the per-state failure of the implicit iteration, batch versus
// single bit equality, evaluation counts, and the handling of Tao's extended copies (compaction, single-state redo,
// distance).
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "support/models.hpp"
#include "support/nan_aware.hpp"
#include "support/phase_space_jacobian.hpp"

namespace test_comparators_properties {

using namespace nonsep;
using nonsep::testing::Coupled2D;
using nonsep::testing::Paper1D;

namespace {

using Vector = std::vector<double>;
using Map = std::function<Vector(const Vector&)>;

const HamiltonianForm forms[] = {HamiltonianForm::TTV, HamiltonianForm::VVT};

// max |J^T Omega J - Omega| of the map's Jacobian J by central differences (support/finite_difference.hpp), for
// the variables ordered (positions..., momenta...). Zero for a symplectic map up to the differencing error (~1e-9);
// NaN when the map is not finite.
double symplecticity_defect(const Map& map, const Vector& z0) {
  return nonsep::testing::symplecticity_defect(nonsep::testing::jacobian_by_differences(map, z0, 1e-6));
}

Vector concat(std::span<const double> a, std::span<const double> b) {
  Vector v(a.begin(), a.end());
  v.insert(v.end(), b.begin(), b.end());
  return v;
}

// One Gauss-Legendre step as a map of z = (q, p).
template <class M>
Map gauss_map(const M& model, HamiltonianForm form, int order, double dt) {
  return [=](const Vector& z) {
    const std::size_t n = z.size() / 2;
    auto x = PhaseSpaceBatch::single(std::span(z).first(n), std::span(z).last(n));
    GaussLegendre(form, order).step(model, x, dt);
    return concat(x.q(), x.p());
  };
}

// One step of Tao's integrator as a map of the extended point (q, x, p, y) (positions first: dq^dp + dx^dy).
template <class M>
Map tao_extended_map(const M& model, HamiltonianForm form, int order, double dt) {
  return [=](const Vector& z) {
    const std::size_t n = z.size() / 4;
    const std::span<const double> all(z);
    auto x = PhaseSpaceBatch::single(all.first(n), all.subspan(2 * n, n));
    auto copies = PhaseSpaceBatch::single(all.subspan(n, n), all.subspan(3 * n, n));
    TaoExtendedPhaseSpace(form, order).step(model, x, copies, dt);
    return concat(concat(x.q(), copies.q()), concat(x.p(), copies.p()));
  };
}

double max_difference(const Vector& a, const Vector& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = testing::max_or_nan(d, std::abs(a[i] - b[i]));
  return d;
}

PhaseSpaceBatch three_states() {
  PhaseSpaceBatch batch(2, 3);
  const double qs[] = {0.5, 0.1, -0.2, 0.3, 0.9, -0.7}, ps[] = {0.1, 0.2, 0.3, -0.4, 0.0, 0.25};
  std::copy(std::begin(qs), std::end(qs), batch.q().begin());
  std::copy(std::begin(ps), std::end(ps), batch.p().begin());
  return batch;
}

}  // namespace

// Tao's step, built by the catalogue, as a map of the extended point (q, x, p, y).
template <class M>
Map catalogue_tao_extended_map(const M& model, const IntegratorSpec& spec, double dt) {
  return [=](const Vector& z) {
    const std::size_t n = z.size() / 4;
    const std::span<const double> all(z);
    auto x = PhaseSpaceBatch::single(all.first(n), all.subspan(2 * n, n));
    auto copies = PhaseSpaceBatch::single(all.subspan(n, n), all.subspan(3 * n, n));
    auto tao = std::get<TaoExtendedPhaseSpace>(Integrator(spec).stepper());
    tao.step(model, x, copies, dt);
    return concat(concat(x.q(), copies.q()), concat(x.p(), copies.p()));
  };
}

// The specs of every order of every catalogue scheme up to order 2 (Chin) or 6 (comparators).
std::vector<IntegratorSpec> catalogue_specs(HamiltonianForm form) {
  std::vector<IntegratorSpec> specs;
  for (const auto& scheme : scheme_catalogue())
    for (const Fraction& order : scheme.orders()) {
      if (scheme.family == "chin" && order.value() > 2.0) break;
      // Order 2/3 of triplet and mpe is the basic step itself (no composition, one term).
      if (scheme.family == "chin" && scheme.highest_order_index > 1 && order == Fraction(2, 3)) continue;
      IntegratorSpec spec = default_spec(scheme, form);
      for (const auto& parameter : scheme.parameters) {
        if (parameter.name == "order") set_option(spec, parameter, order);
        if (parameter.name == "stages") set_option(spec, parameter, static_cast<double>(order.numerator() / 2));
      }
      specs.push_back(spec);
    }
  return specs;
}

TEST_CASE("every catalogue scheme: the one-step map is symplectic exactly as its description says") {
  // Symplectic on (q, p): Chin's basic and triplet, implicit midpoint, Gauss; Tao on the extended phase space only;
  // MPE not at all (a defect far above the differencing noise, ~1e-10).
  int tested = 0;
  for (const auto form : forms)
    for (const IntegratorSpec& spec : catalogue_specs(form)) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(spec.scheme);
      CAPTURE(Integrator(spec).describe().order.to_string());
      const bool symplectic = find_scheme(spec.scheme)->symplectic;
      ++tested;
      if (spec.scheme == "tao") {
        // Copies apart from (q, p), as they are during a run.
        CHECK(symplecticity_defect(catalogue_tao_extended_map(Paper1D{}, spec, 0.05), {1.2, 1.19, 0.5, 0.51}) < 1e-8);
        CHECK(symplecticity_defect(catalogue_tao_extended_map(Coupled2D{}, spec, 0.05),
                                   {0.6, -0.4, 0.61, -0.41, 0.3, 0.2, 0.29, 0.21}) < 1e-8);
        // The projection to (q, p) with the copies started on it is not symplectic.
        CHECK(symplecticity_defect(testing::integrator_map(Paper1D{}, spec, 0.05), {1.2, 0.5}) > 1e-6);
        continue;
      }
      // dt = 0.02 for the symplectic ones: at 0.05 the order-2 triplet's largest basic step throws paper1d to
      // infinity; 0.1 for MPE, as in test_core_properties.cpp.
      const double dt = symplectic ? 0.02 : 0.1;
      const double defect_1d = symplecticity_defect(testing::integrator_map(Paper1D{}, spec, dt), {1.2, 0.5});
      const double defect_2d =
          symplecticity_defect(testing::integrator_map(Coupled2D{}, spec, dt), {0.6, -0.4, 0.3, 0.2});
      if (symplectic) {
        CHECK(defect_1d < 1e-8);
        CHECK(defect_2d < 1e-8);
      } else {
        CHECK(defect_1d > 1e-6);
        CHECK(defect_2d > 1e-6);
      }
    }
  CHECK(tested >= 2 * 12);
}

TEST_CASE("Gauss-Legendre tableaux of 1 to 8 stages: order conditions, symmetry, and mu_ij + mu_ji = 1 exactly") {
  for (int stages = 1; stages <= GaussLegendreTableau::max_stages; ++stages) {
    CAPTURE(stages);
    const auto t = GaussLegendreTableau::for_stages(stages);
    const auto s = static_cast<std::size_t>(stages);
    // B(2s): sum_i b_i c_i^(k-1) = 1/k for k = 1 .. 2s (the quadrature's order); C(s): sum_j a_ij c_j^(k-1) =
    // c_i^k / k for k = 1 .. s (collocation). Both hold to a few ulp of the rounded coefficients.
    for (std::size_t k = 1; k <= 2 * s; ++k) {
      double sum = 0.0;
      for (std::size_t i = 0; i < s; ++i) sum += t.b[i] * std::pow(t.c[i], static_cast<double>(k - 1));
      CHECK(std::abs(sum - 1.0 / static_cast<double>(k)) < 4e-16);
    }
    for (std::size_t i = 0; i < s; ++i)
      for (std::size_t k = 1; k <= s; ++k) {
        double sum = 0.0;
        for (std::size_t j = 0; j < s; ++j) sum += t.a[i * s + j] * std::pow(t.c[j], static_cast<double>(k - 1));
        CHECK(std::abs(sum - std::pow(t.c[i], static_cast<double>(k)) / static_cast<double>(k)) < 1e-15);
      }
    for (std::size_t i = 0; i < s; ++i) {
      CHECK(t.b[i] == t.b[s - 1 - i]);
      CHECK(t.c[i] + t.c[s - 1 - i] == 1.0);
      CHECK(t.mu[i * s + i] == 0.5);
      for (std::size_t j = 0; j < s; ++j) {
        CHECK(t.mu[i * s + j] + t.mu[j * s + i] == 1.0);  // symplectic in floating point
        CHECK(std::abs(t.mu[i * s + j] * t.b[j] - t.a[i * s + j]) < 1e-16);
      }
      // The starting values extrapolate the collocation polynomial exactly for degree <= s:
      // sum_j nu_ij b_j c_j^(k-1) = ((1 + c_i)^k - 1) / k.
      // The terms grow with s (|nu| up to about 300 for 8 stages): the bound is a few ulp of their magnitudes.
      for (std::size_t k = 1; k <= s; ++k) {
        double sum = 0.0, magnitude = 0.0;
        for (std::size_t j = 0; j < s; ++j) {
          const double term = t.nu[i * s + j] * t.b[j] * std::pow(t.c[j], static_cast<double>(k - 1));
          sum += term;
          magnitude += std::abs(term);
        }
        const double exact = (std::pow(1.0 + t.c[i], static_cast<double>(k)) - 1.0) / static_cast<double>(k);
        CHECK(std::abs(sum - exact) <= 4.0 * static_cast<double>(s) * 2.3e-16 * magnitude);
      }
    }
  }
  // The closed forms of two and three stages (Hairer, Lubich, Wanner, Table II.1.1 and II.1.2).
  const auto two = GaussLegendreTableau::for_stages(2), three = GaussLegendreTableau::for_stages(3);
  CHECK(two.c[0] == doctest::Approx(0.5 - std::sqrt(3.0) / 6.0).epsilon(1e-15));
  CHECK(two.a[1] == doctest::Approx(0.25 - std::sqrt(3.0) / 6.0).epsilon(1e-15));
  CHECK(three.b[1] == doctest::Approx(4.0 / 9.0).epsilon(1e-15));
  CHECK(three.a[2] == doctest::Approx(5.0 / 36.0 - std::sqrt(15.0) / 30.0).epsilon(1e-15));
  CHECK_THROWS_AS(GaussLegendreTableau::for_stages(9), InvalidArgument);
  CHECK_THROWS_AS(GaussLegendreTableau::for_stages(0), InvalidArgument);
}

TEST_CASE("a step of dt then one of -dt returns to the start: Gauss on (q, p), Tao on (q, p, x, y)") {
  for (const auto form : forms)
    for (const int order : {2, 4, 6, 8, 16}) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(order);
      const Vector z{0.6, -0.4, 0.3, 0.2}, extended{0.6, -0.4, 0.61, -0.41, 0.3, 0.2, 0.29, 0.21};
      const Vector forward = gauss_map(Coupled2D{}, form, order, 0.02)(z);
      CHECK(max_difference(forward, z) > 1e-3);  // it did move
      CHECK(max_difference(gauss_map(Coupled2D{}, form, order, -0.02)(forward), z) < 1e-13);
      if (order > 6) continue;  // Tao's orders end at 6
      const Vector tao_forward = tao_extended_map(Coupled2D{}, form, order, 0.02)(extended);
      CHECK(max_difference(tao_forward, extended) > 1e-3);
      CHECK(max_difference(tao_extended_map(Coupled2D{}, form, order, -0.02)(tao_forward), extended) < 1e-13);
    }
}

TEST_CASE("Gauss-Legendre: a state whose iteration does not converge fails alone, named, at its starting point") {
  // Paper1D at (3, 3): the Lipschitz constant of (dH/dp, -dH/dq) is about 290, so dt = 0.05 makes the iteration
  // diverge; at (0.5, 0.2) it is about 2.6 and the iteration contracts.
  for (const int order : {2, 4, 6}) {
    CAPTURE(order);
    PhaseSpaceBatch batch(1, 2);
    batch.q()[0] = 0.5, batch.p()[0] = 0.2, batch.q()[1] = 3.0, batch.p()[1] = 3.0;
    const PhaseSpaceBatch start = batch;
    GaussLegendre gauss(HamiltonianForm::TTV, order);
    const auto failures = gauss.try_step(Paper1D{}, batch, 0.05);
    REQUIRE(failures.size() == 1);
    CHECK(failures[0].state == 1);
    MESSAGE("order " << order << ": " << failures[0].reason);
    CHECK(batch.q()[1] == 3.0);
    CHECK(batch.p()[1] == 3.0);
    auto alone = PhaseSpaceBatch::single(start.q(0), start.p(0));
    GaussLegendre(HamiltonianForm::TTV, order).step(Paper1D{}, alone, 0.05);
    CHECK(alone == PhaseSpaceBatch::single(batch.q(0), batch.p(0)));
    // step() throws ModelError naming the state, which the host's isolate_failures turns into a retirement.
    batch = start;
    try {
      gauss.step(Paper1D{}, batch, 0.05);
      FAIL("no ModelError");
    } catch (const ModelError& error) {
      CHECK(std::string(error.what()).find("state 1 of 2") != std::string::npos);
      CHECK(std::string(error.what()).find("state 0") == std::string::npos);
    }
    auto failing = PhaseSpaceBatch::single(start.q(1), start.p(1));
    try {
      gauss.step(Paper1D{}, failing, 0.05);
      FAIL("no ModelError");
    } catch (const ModelError& error) {
      CHECK(std::string(error.what()).find("fixed-point iteration failed (") != std::string::npos);
    }
    // A huge step fails even near the equilibrium; a small one from the failing state converges.
    auto near = PhaseSpaceBatch::single(Vector{0.01}, Vector{0.01});
    CHECK_THROWS_AS(gauss.step(Paper1D{}, near, 50.0), ModelError);
    CHECK_NOTHROW(gauss.step(Paper1D{}, failing, 1e-4));
  }
  CHECK_THROWS_AS(GaussLegendre(HamiltonianForm::TTV, 18), InvalidArgument);
  CHECK_THROWS_AS(GaussLegendre(HamiltonianForm::TTV, 3), InvalidArgument);
  CHECK_THROWS_AS(GaussLegendre(HamiltonianForm::TTV, 2, 0), InvalidArgument);
  CHECK_THROWS_AS(TaoExtendedPhaseSpace(HamiltonianForm::TTV, 3), InvalidArgument);
  CHECK_THROWS_AS(TaoExtendedPhaseSpace(HamiltonianForm::TTV, 2, 0.0), InvalidArgument);
  CHECK_THROWS_AS(TaoExtendedPhaseSpace(HamiltonianForm::TTV, 2, std::nan("")), InvalidArgument);
}

TEST_CASE("comparators: stepping a batch equals stepping each state alone, bit for bit, at the same cost") {
  for (const auto form : forms)
    for (const int order : {2, 4, 6}) {
      CAPTURE(static_cast<int>(form));
      CAPTURE(order);
      auto tao_batch = three_states(), gauss_batch = three_states();
      TaoExtendedPhaseSpace tao(form, order);
      GaussLegendre gauss(form, order);
      for (int s = 0; s < 10; ++s) {
        tao.step(Coupled2D{}, tao_batch, 0.01);
        gauss.step(Coupled2D{}, gauss_batch, 0.02);
      }
      std::uint64_t tao_alone = 0, gauss_alone = 0;
      for (std::size_t b = 0; b < 3; ++b) {
        const auto start = three_states();
        auto x = PhaseSpaceBatch::single(start.q(b), start.p(b)), y = x;
        TaoExtendedPhaseSpace tao_one(form, order);
        GaussLegendre gauss_one(form, order);
        for (int s = 0; s < 10; ++s) {
          tao_one.step(Coupled2D{}, x, 0.01);
          gauss_one.step(Coupled2D{}, y, 0.02);
        }
        CHECK(x == PhaseSpaceBatch::single(tao_batch.q(b), tao_batch.p(b)));
        CHECK(tao_one.copies() == tao.copy_of(b));
        CHECK(y == PhaseSpaceBatch::single(gauss_batch.q(b), gauss_batch.p(b)));
        tao_alone += tao_one.evaluations().grad_H;
        gauss_alone += gauss_one.evaluations().grad_H;
      }
      CHECK(tao.evaluations().grad_H == tao_alone);
      CHECK(gauss.evaluations().grad_H == gauss_alone);
    }
}

TEST_CASE("evaluation counts: Tao 3 grad H per Strang step plus one at the start, Gauss s per iteration") {
  for (const int order : {2, 4, 6}) {
    CAPTURE(order);
    const std::uint64_t strang = order == 2 ? 1 : order == 4 ? 3 : 9;
    TaoExtendedPhaseSpace tao(HamiltonianForm::TTV, order);
    auto batch = three_states();
    // Steps of different sizes, one negative: the cached gradient belongs to the point, not to dt.
    for (const double dt : {0.01, 0.02, -0.005, 0.013, 0.01, 0.01, 0.004}) tao.step(Coupled2D{}, batch, dt);
    CHECK(tao.evaluations().grad_H == 3 * (3 * strang * 7 + 1));
    CHECK(tao.describe().grad_H_per_step == 3 * strang);
    CHECK(tao.evaluations().grad_T + tao.evaluations().grad_V == 0);
    // The cache is the gradient at (q, y): a change of p from outside leaves it valid, a change of q does not
    // (one more evaluation, never a stale one).
    batch.p()[0] += 0.1;
    tao.step(Coupled2D{}, batch, 0.01);
    CHECK(tao.evaluations().grad_H == 3 * (3 * strang * 8 + 1));
    batch.q()[0] += 0.1;
    tao.step(Coupled2D{}, batch, 0.01);
    CHECK(tao.evaluations().grad_H == 3 * (3 * strang * 9 + 2));

    GaussLegendre gauss(HamiltonianForm::TTV, order);
    auto y = three_states();
    std::uint64_t iterations = 0;
    for (int s = 0; s < 5; ++s) {
      gauss.step(Coupled2D{}, y, 0.02);
      for (const int i : gauss.iterations()) {
        CHECK(i > 2);
        CHECK(i < 40);
        iterations += static_cast<std::uint64_t>(i);
      }
    }
    MESSAGE("gauss order " << order << ": " << iterations / 15.0 << " iterations per step at dt = 0.02");
    CHECK(gauss.evaluations().grad_H == static_cast<std::uint64_t>(order / 2) * iterations);
    CHECK(gauss.describe().grad_H_per_iteration == static_cast<std::uint64_t>(order / 2));
    CHECK(gauss.describe().integrator_description().order == Fraction(order));
  }
}

TEST_CASE("Tao's extended copies: start on (q, p), stay close, compact with the batch, redo one state alone") {
  TaoExtendedPhaseSpace tao(HamiltonianForm::TTV, 4);
  auto batch = three_states();
  std::vector<double> distance(3);
  tao.step(Coupled2D{}, batch, 0.01);
  REQUIRE(tao.copies().count() == 3);
  for (int s = 0; s < 99; ++s) tao.step(Coupled2D{}, batch, 0.01);
  tao.copy_distance(batch, distance);
  MESSAGE("distance between the copies after 100 steps of 0.01: " << distance[0] << ", " << distance[1] << ", "
                                                                  << distance[2]);
  for (const double d : distance) {
    CHECK(d > 0.0);   // the copies separate at the size of the scheme's error ...
    CHECK(d < 1e-6);  // ... and the binding keeps them together
  }
  // Retiring state 1 and compacting batch and copies alike continues states 0 and 2 as if nothing happened.
  auto continued = batch;
  TaoExtendedPhaseSpace whole = tao;
  PhaseSpaceBatch compacted(2, 2);
  for (std::size_t b : {0u, 2u}) {
    std::copy(batch.q(b).begin(), batch.q(b).end(), compacted.q(b / 2).begin());
    std::copy(batch.p(b).begin(), batch.p(b).end(), compacted.p(b / 2).begin());
  }
  tao.compact_copies({false, true, false});
  CHECK(tao.copies().count() == 2);
  // State 1 redone alone with its saved copy (the host's state-by-state retry), through the caller-held overload.
  auto one = PhaseSpaceBatch::single(batch.q(1), batch.p(1));
  auto one_copy = whole.copy_of(1);
  TaoExtendedPhaseSpace single(HamiltonianForm::TTV, 4);
  for (int s = 0; s < 10; ++s) {
    tao.step(Coupled2D{}, compacted, 0.01);
    whole.step(Coupled2D{}, continued, 0.01);
    single.step(Coupled2D{}, one, one_copy, 0.01);
  }
  for (std::size_t b : {0u, 2u}) {
    CHECK(PhaseSpaceBatch::single(compacted.q(b / 2), compacted.p(b / 2)) ==
          PhaseSpaceBatch::single(continued.q(b), continued.p(b)));
    CHECK(tao.copy_of(b / 2) == whole.copy_of(b));
  }
  CHECK(one == PhaseSpaceBatch::single(continued.q(1), continued.p(1)));
  CHECK(one_copy == whole.copy_of(1));
  // Copies of another shape are refused; reset_copies starts them anew from the states.
  auto wrong = three_states();
  CHECK_THROWS_AS(tao.step(Coupled2D{}, wrong, 0.01), InvalidArgument);
  CHECK_THROWS_AS(tao.compact_copies({true}), InvalidArgument);
  tao.reset_copies();
  tao.step(Coupled2D{}, wrong, 0.01);
  CHECK(tao.copies().count() == 3);
  tao.restore_copies(whole.copies());
  std::vector<double> expected(3);
  tao.copy_distance(continued, distance);
  whole.copy_distance(continued, expected);
  CHECK(distance == expected);
}

TEST_CASE("Gauss-Legendre's starting values: fewer iterations, the same map, kept through compaction, redo and save") {
  for (const int order : {2, 6, 16}) {
    CAPTURE(order);
    // From the last step's stages: the same states to round-off as from Z = 0, in fewer iterations.
    auto extrapolated = three_states(), from_zero = three_states();
    GaussLegendre gauss(HamiltonianForm::TTV, order), zero(HamiltonianForm::TTV, order, 100, false);
    for (int s = 0; s < 50; ++s) {
      gauss.step(Coupled2D{}, extrapolated, 0.02);
      zero.step(Coupled2D{}, from_zero, 0.02);
      if (s == 0) CHECK(extrapolated == from_zero);  // the first step starts from Z = 0 too
    }
    MESSAGE("grad H over 50 steps: " << gauss.evaluations().grad_H << " extrapolated, " << zero.evaluations().grad_H
                                     << " from zero");
    // Measured: 11% fewer for the midpoint rule (its polynomial is a line), 32% for 3 stages, 69% for 8.
    const double saved =
        1.0 - static_cast<double>(gauss.evaluations().grad_H) / static_cast<double>(zero.evaluations().grad_H);
    CHECK(saved > (order == 2 ? 0.05 : order == 6 ? 0.25 : 0.5));
    CHECK(max_difference(nonsep::testing::phase_point(extrapolated), nonsep::testing::phase_point(from_zero)) < 1e-13);
    // Retiring state 1 and compacting continues states 0 and 2 bit for bit; state 1 redone alone from a copy of
    // the stepper before the step (the host's state-by-state retry) is the batch's state 1 bit for bit; a stepper
    // restored from save_state continues as the original.
    GaussLegendre whole = gauss, compacted_stepper = gauss, part_stepper = gauss, restored(HamiltonianForm::TTV, order);
    restored.restore_state(gauss.save_state(extrapolated));
    // dt, q, p, their rounding errors (4 n) and the L of s = order/2 stages (2 s n), n = 2.
    CHECK(gauss.save_state(extrapolated).columns.at(0).per_state == 1 + 4 * 2 + 2 * static_cast<std::size_t>(order));
    auto continued = extrapolated, restored_batch = extrapolated;
    PhaseSpaceBatch compacted(2, 2);
    for (std::size_t b : {0u, 2u}) {
      std::copy(extrapolated.q(b).begin(), extrapolated.q(b).end(), compacted.q(b / 2).begin());
      std::copy(extrapolated.p(b).begin(), extrapolated.p(b).end(), compacted.p(b / 2).begin());
    }
    compacted_stepper.compact({false, true, false});
    auto one = PhaseSpaceBatch::single(extrapolated.q(1), extrapolated.p(1));
    const GaussLegendre before = part_stepper;
    part_stepper.step_part(Coupled2D{}, one, before, 1, 3, 0.02);
    whole.step(Coupled2D{}, continued, 0.02);
    compacted_stepper.step(Coupled2D{}, compacted, 0.02);
    restored.step(Coupled2D{}, restored_batch, 0.02);
    CHECK(one == PhaseSpaceBatch::single(continued.q(1), continued.p(1)));
    CHECK(restored_batch == continued);
    for (std::size_t b : {0u, 2u})
      CHECK(PhaseSpaceBatch::single(compacted.q(b / 2), compacted.p(b / 2)) ==
            PhaseSpaceBatch::single(continued.q(b), continued.p(b)));
    // A state that does not continue its last step (moved, or another dt) starts from Z = 0: the zero-start map.
    auto moved = continued, moved_zero = continued;
    moved.q()[0] += 1e-3;
    moved_zero.q()[0] += 1e-3;
    GaussLegendre fresh(HamiltonianForm::TTV, order, 100, false);
    whole.step(Coupled2D{}, moved, 0.02);
    fresh.step(Coupled2D{}, moved_zero, 0.02);
    CHECK(PhaseSpaceBatch::single(moved.q(0), moved.p(0)) == PhaseSpaceBatch::single(moved_zero.q(0), moved_zero.p(0)));
  }
}

namespace {
// H = 0: every derivative vanishes, so Tao's step is the binding flow phi_C alone.
struct Free1D {
  std::size_t dimension() const { return 1; }
  static void zero(std::span<double> out, std::size_t count, std::size_t per_state) {
    std::fill_n(out.begin(), count * per_state, 0.0);
  }
  void grad_T(std::span<const double>, std::span<double> out, std::size_t count) const { zero(out, count, 1); }
  void grad_V(std::span<const double>, std::span<double> out, std::size_t count) const { zero(out, count, 1); }
  void hessian_T(std::span<const double>, std::span<double> out, std::size_t count) const { zero(out, count, 1); }
  void hessian_V(std::span<const double>, std::span<double> out, std::size_t count) const { zero(out, count, 1); }
  void d3T(std::span<const double>, std::span<const double>, std::span<double> out, std::size_t count) const {
    zero(out, count, 1);
  }
  void d3V(std::span<const double>, std::span<const double>, std::span<double> out, std::size_t count) const {
    zero(out, count, 1);
  }
};
}  // namespace

TEST_CASE("with H = 0 Tao's step is the exact flow of the binding omega (|q - x|^2 + |p - y|^2)/2") {
  // Reference: Hamilton's equations of omega H_C by Runge-Kutta-Fehlberg 7(8), s = (q, x, p, y).
  const double omega = 20.0, dt = 0.3;
  auto rhs = [omega](const std::vector<double>& s, std::vector<double>& d) {
    d[0] = omega * (s[2] - s[3]);
    d[1] = -omega * (s[2] - s[3]);
    d[2] = -omega * (s[0] - s[1]);
    d[3] = omega * (s[0] - s[1]);
  };
  const auto reference = nonsep::reference::hamiltonian_flow(rhs, {1.0, 0.2, 0.5, -0.3}, dt);
  for (const int order : {2, 4, 6}) {
    CAPTURE(order);
    auto x = PhaseSpaceBatch::single(Vector{1.0}, Vector{0.5});
    auto copies = PhaseSpaceBatch::single(Vector{0.2}, Vector{-0.3});
    TaoExtendedPhaseSpace(HamiltonianForm::TTV, order, omega).step(Free1D{}, x, copies, dt);
    CHECK(max_difference({x.q()[0], copies.q()[0], x.p()[0], copies.p()[0]}, reference) < 1e-12);
  }
}

TEST_CASE("the distance between Tao's copies shrinks with the scheme's order") {
  // Coupled2D from (0.5, 0.1; 0.1, 0.2) to t = 1, omega = 20: distances 4.1e-5, 1.0e-5, 2.5e-6 (order 2), 9.6e-7,
  // 6.0e-8, 3.8e-9 (order 4), 4.2e-8, 7.1e-10, 1.1e-11 (order 6) for dt = 0.01, 0.005, 0.0025.
  for (const int order : {2, 4, 6}) {
    CAPTURE(order);
    std::vector<double> distances;
    for (const double dt : {0.01, 0.005, 0.0025}) {
      TaoExtendedPhaseSpace tao(HamiltonianForm::TTV, order);
      PhaseSpaceBatch x(2, 1);
      x.q()[0] = 0.5, x.q()[1] = 0.1, x.p()[0] = 0.1, x.p()[1] = 0.2;
      for (int s = 0; s < static_cast<int>(std::lround(1.0 / dt)); ++s) tao.step(Coupled2D{}, x, dt);
      double d = 0;
      tao.copy_distance(x, std::span<double>(&d, 1));
      distances.push_back(d);
    }
    CHECK(std::abs(std::log2(distances[1] / distances[2]) - order) < 0.1);
    CHECK(distances[2] > 0.0);
  }
}

}  // namespace test_comparators_properties
