// The tangent maps of the comparators (gauss with 1, 2, 3 stages, implicit_midpoint, tao of orders 2, 4, 6) and the
// directional derivative of grad H they evaluate (the SDK's hvp_H): each is the derivative of what it differentiates
// (central differences), in both forms and with a separable part K + U; Gauss's is symplectic to round-off, and its
// linear stages solved directly and by iteration agree; Tao's
// copies' part follows a renormalisation of the vectors and its private state restores bit for bit; a symplectic
// scheme's full Lyapunov spectrum sums to zero. The models are the shipped plugins' classes behind the SDK's adapter.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "lattice_chain/lattice_chain.hpp"
#include "nonsep/core.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "paper2d/paper2d.hpp"
#include "support/finite_difference.hpp"
#include "support/phase_space_jacobian.hpp"
#include "variable_mass2d/variable_mass2d.hpp"

namespace test_comparator_tangent_maps {

using namespace nonsep;

namespace {

const std::array<HamiltonianForm, 2> forms{HamiltonianForm::TTV, HamiltonianForm::VVT};

using Paper2DModel = sdk::ModelAdapter<Paper2D>;
using VariableMassModel = sdk::ModelAdapter<VariableMass2D>;

// Every comparator spec: gauss 1..3 stages (1 as implicit_midpoint), tao 2, 4, 6.
std::vector<IntegratorSpec> comparator_specs(HamiltonianForm form) {
  std::vector<IntegratorSpec> specs;
  IntegratorSpec midpoint{"implicit_midpoint"};
  midpoint.form = form;
  specs.push_back(midpoint);
  for (int stages : {1, 2, 3, 4, 8}) {
    IntegratorSpec gauss{"gauss", GaussOptions{stages}};
    gauss.form = form;
    specs.push_back(gauss);
  }
  for (int order : {2, 4, 6}) {
    IntegratorSpec tao{"tao", TaoOptions{Fraction(order)}};
    tao.form = form;
    specs.push_back(tao);
  }
  return specs;
}

std::string name_of(const IntegratorSpec& spec) {
  return spec.scheme +
         (spec.scheme == "gauss" ? " " + std::to_string(std::get<GaussOptions>(spec.options).stages) + " stages"
                                 : " order " + Integrator(spec).describe().order.to_string()) +
         (spec.form == HamiltonianForm::TTV ? " TTV" : " VVT");
}

template <class M>
Eigen::MatrixXd tangent_jacobian(const M& model, const IntegratorSpec& spec, PhaseSpaceBatch x, double dt, int steps) {
  auto tangents = testing::identity_tangents(x.dimension());
  TangentIntegrator integrator(spec);
  for (int s = 0; s < steps; ++s) integrator.step(model, x, tangents, dt);
  return testing::as_matrix(tangents);
}

// max |a - b| / max |b|.
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

// hvp_H against central differences of grad H along the tangent, at (q, p) along (dq, dp).
// `difference_form`: the form of the differenced gradient (another than `form` for a negative control).
template <class M>
double hvp_error(const M& model, HamiltonianForm form, const std::vector<double>& q, const std::vector<double>& p,
                 const std::vector<double>& dq, const std::vector<double>& dp,
                 std::optional<HamiltonianForm> difference_form = std::nullopt) {
  const std::size_t n = q.size();
  std::vector<double> out_q(n), out_p(n);
  model.hvp_H(form, q, p, dq, dp, out_q, out_p, 1);
  const auto gradient = [&](const std::vector<double>& z) {
    HamiltonianGradient grad(difference_form.value_or(form));
    std::vector<double> zq(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(n)),
        zp(z.begin() + static_cast<std::ptrdiff_t>(n), z.end());
    std::vector<double> gq(n), gp(n);
    grad.evaluate(model, zq, zp, gq, gp, 1);
    gq.insert(gq.end(), gp.begin(), gp.end());
    return gq;
  };
  std::vector<double> z = q, direction = dq;
  z.insert(z.end(), p.begin(), p.end());
  direction.insert(direction.end(), dp.begin(), dp.end());
  const double h = 1e-5;
  std::vector<double> plus = z, minus = z;
  for (std::size_t i = 0; i < 2 * n; ++i) {
    plus[i] += h * direction[i];
    minus[i] -= h * direction[i];
  }
  const auto g_plus = gradient(plus), g_minus = gradient(minus);
  double error = 0.0, size = 0.0;
  for (std::size_t i = 0; i < 2 * n; ++i) {
    const double exact = i < n ? out_q[i] : out_p[i - n];
    const double difference = (g_plus[i] - g_minus[i]) / (2 * h);
    error = std::max(error, std::abs(exact - difference));
    size = std::max(size, std::abs(exact));
  }
  return error / size;
}

}  // namespace

TEST_CASE("hvp_H is the derivative of grad H along the tangent: both forms, K + U, gradient templates, T and V") {
  const Paper2DModel paper2d;
  const sdk::ModelAdapter<Paper2D, sdk::Derivatives::automatic> paper2d_automatic;
  const VariableMassModel variable_mass;
  const auto lattice = sdk::ModelAdapter<LatticeChainModel<64>>::from_json(R"({"sites": 5})");
  static_assert(sdk::ModelAdapter<LatticeChainModel<64>>::fourth_by_gradients);
  static_assert(!sdk::ModelAdapter<Paper2D, sdk::Derivatives::automatic>::fourth_by_gradients);
  for (const auto form : forms) {
    CAPTURE(static_cast<int>(form));
    const std::vector<double> q{0.5, -0.3}, p{0.4, 1.2}, dq{0.3, -0.7}, dp{0.9, 0.2};
    CHECK(hvp_error(paper2d, form, q, p, dq, dp) < 1e-8);
    CHECK(hvp_error(paper2d_automatic, form, q, p, dq, dp) < 1e-8);
    CHECK(hvp_error(variable_mass, form, q, p, dq, dp) < 1e-8);
    const std::vector<double> lq{0.1, -0.2, 0.3, 0.05, -0.15}, lp{0.4, 0.1, -0.3, 0.2, 0.0},
        ldq{1.0, 0.0, -0.5, 0.25, 0.3}, ldp{-0.2, 0.6, 0.1, 0.0, 0.8};
    CHECK(hvp_error(lattice, form, lq, lp, ldq, ldp) < 1e-8);
    // The negative control: differences of the other form's gradient disagree.
    const auto other = form == HamiltonianForm::TTV ? HamiltonianForm::VVT : HamiltonianForm::TTV;
    CHECK(hvp_error(paper2d, form, q, p, dq, dp, other) > 1e-2);
  }
}

TEST_CASE("the comparators' tangent maps are the derivative of their maps (central differences, relative 1e-7)") {
  const Paper2DModel paper2d;
  const VariableMassModel variable_mass;
  const auto x2 = PhaseSpaceBatch::single(std::vector{0.5, 0.1}, std::vector{0.2, 1.5});
  for (const auto form : forms)
    for (const auto& spec : comparator_specs(form)) {
      CAPTURE(name_of(spec));
      const auto check = [&](const auto& model, double dt) {
        // Three steps, so that Tao's copies have moved apart and the cached gradient is reused.
        const Eigen::MatrixXd exact = tangent_jacobian(model, spec, x2, dt, 3);
        const Eigen::MatrixXd differences = testing::jacobian_by_differences(
            testing::integrator_map(model, spec, dt, 3), testing::phase_point(x2), 1e-5);
        CHECK(relative_difference(exact, differences) < 1e-7);
        CHECK((exact - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff() > 1e-3);  // it moved
      };
      check(paper2d, 0.01);
      check(variable_mass, 0.02);
    }
}

TEST_CASE("the tangent map of Gauss-Legendre is symplectic to round-off, and a step of dt then -dt is the identity") {
  const Paper2DModel paper2d;
  const VariableMassModel variable_mass;
  for (const auto form : forms)
    for (const auto& spec : comparator_specs(form)) {
      if (spec.scheme == "tao") continue;
      CAPTURE(name_of(spec));
      const auto x = PhaseSpaceBatch::single(std::vector{0.6, -0.4}, std::vector{0.3, 0.2});
      const double defects[] = {testing::symplecticity_defect(tangent_jacobian(paper2d, spec, x, 0.02, 1), true),
                                testing::symplecticity_defect(tangent_jacobian(variable_mass, spec, x, 0.02, 1), true)};
      for (const double defect : defects) {
        CAPTURE(defect);
        CHECK(defect < 1e-13);
      }
      auto y = x;
      auto tangents = testing::identity_tangents(2);
      TangentIntegrator integrator(spec);
      integrator.step(paper2d, y, tangents, 0.03);
      integrator.step(paper2d, y, tangents, -0.03);
      CHECK((testing::as_matrix(tangents) - Eigen::MatrixXd::Identity(4, 4)).cwiseAbs().maxCoeff() < 1e-12);
    }
}

TEST_CASE("Gauss-Legendre's linear stages solved directly and by iteration give the same tangent map to round-off") {
  // Five sites, 2n = 10: one vector per state is iterated, three are solved directly (with 1 to 3 stages).
  const auto lattice = sdk::ModelAdapter<LatticeChainModel<64>>::from_json(R"({"sites": 5})");
  CHECK_FALSE(TangentGaussLegendre::solves_directly(5, 1, 3));
  CHECK(TangentGaussLegendre::solves_directly(5, 3, 3));
  CHECK_FALSE(TangentGaussLegendre::solves_directly(5, 3, 4));  // the LU would pass 40 x 40
  CHECK(TangentGaussLegendre::solves_directly(1, 1, 8));
  const std::vector<double> q{0.1, -0.2, 0.3, 0.05, -0.15}, p{0.4, 0.1, -0.3, 0.2, 0.0};
  const std::vector<double> dq{1.0, 0.0, -0.5, 0.25, 0.3}, dp{-0.2, 0.6, 0.1, 0.0, 0.8};
  for (int stages : {1, 2, 3}) {
    CAPTURE(stages);
    const IntegratorSpec gauss{"gauss", GaussOptions{stages}};
    auto x1 = PhaseSpaceBatch::single(q, p), x3 = x1;
    auto one = PhaseSpaceBatch::single(dq, dp);
    PhaseSpaceBatch three(5, 3);
    for (std::size_t j = 0; j < 3; ++j) {
      std::copy(dq.begin(), dq.end(), three.q(j).begin());
      std::copy(dp.begin(), dp.end(), three.p(j).begin());
      three.q(j)[j] += 0.5;  // the other two vectors differ from the first
    }
    std::copy(dq.begin(), dq.end(), three.q(0).begin());
    TangentIntegrator iterated(gauss, 1), direct(gauss, 3);
    for (int s = 0; s < 5; ++s) {
      iterated.step(lattice, x1, one, 0.05);
      direct.step(lattice, x3, three, 0.05);
    }
    CHECK(std::equal(x1.q().begin(), x1.q().end(), x3.q().begin()));  // the states bit for bit
    double difference = 0.0, size = 0.0;
    for (std::size_t c = 0; c < 5; ++c) {
      difference = std::max({difference, std::abs(one.q()[c] - three.q(0)[c]), std::abs(one.p()[c] - three.p(0)[c])});
      size = std::max({size, std::abs(one.q()[c]), std::abs(one.p()[c])});
    }
    CAPTURE(difference / size);
    CHECK(difference / size < 1e-13);
  }
}

TEST_CASE("Tao's copies' part follows a renormalisation of the vectors: the result is the map's Jacobian times it") {
  const Paper2DModel paper2d;
  for (const auto form : forms)
    for (int order : {2, 4}) {
      IntegratorSpec spec{"tao", TaoOptions{Fraction(order)}};
      spec.form = form;
      CAPTURE(name_of(spec));
      const auto x0 = PhaseSpaceBatch::single(std::vector{0.5, 0.1}, std::vector{0.2, 1.5});
      auto x = x0;
      auto tangents = testing::identity_tangents(2);
      TangentIntegrator integrator(spec);
      Eigen::MatrixXd combination = Eigen::MatrixXd::Identity(4, 4);
      std::array<double, 4> ignored{};
      for (int s = 0; s < 4; ++s) {
        integrator.step(paper2d, x, tangents, 0.01);
        const Eigen::MatrixXd before = testing::as_matrix(tangents);
        orthonormalize_state(tangents, 4, 0, ignored);  // as LyapunovExponents renormalises
        combination = combination * before.inverse() * testing::as_matrix(tangents);
      }
      const Eigen::MatrixXd differences = testing::jacobian_by_differences(
          testing::integrator_map(paper2d, spec, 0.01, 4), testing::phase_point(x0), 1e-5);
      CHECK(relative_difference(testing::as_matrix(tangents), differences * combination) < 1e-7);
    }
}

TEST_CASE(
    "comparator tangents: batch equals single, and Tao's private state saves, restores and compacts bit for bit") {
  const Paper2DModel paper2d;
  const std::vector<double> q{0.5, 0.1, -0.3, 0.4, 0.2, -0.1}, p{0.2, 1.5, 1.0, -0.5, 0.7, 0.3};
  for (const auto& spec : comparator_specs(HamiltonianForm::TTV)) {
    CAPTURE(name_of(spec));
    const std::size_t k = 2;
    auto all = PhaseSpaceBatch(2, 3);
    std::copy(q.begin(), q.end(), all.q().begin());
    std::copy(p.begin(), p.end(), all.p().begin());
    auto all_tangents = PhaseSpaceBatch(2, 3 * k);
    for (std::size_t r = 0; r < 3 * k; ++r) all_tangents.q(r)[r % 2] = all_tangents.p(r)[(r + 1) % 2] = 1.0 + r;
    const auto start = all;
    const auto start_tangents = all_tangents;
    TangentIntegrator batch(spec, k);
    for (int s = 0; s < 3; ++s) batch.step(paper2d, all, all_tangents, 0.01);
    for (std::size_t b = 0; b < 3; ++b) {
      auto one = PhaseSpaceBatch::single(start.q(b), start.p(b));
      PhaseSpaceBatch one_tangents(2, k);
      for (std::size_t j = 0; j < k; ++j) {
        std::copy(start_tangents.q(b * k + j).begin(), start_tangents.q(b * k + j).end(), one_tangents.q(j).begin());
        std::copy(start_tangents.p(b * k + j).begin(), start_tangents.p(b * k + j).end(), one_tangents.p(j).begin());
      }
      TangentIntegrator single(spec, k);
      for (int s = 0; s < 3; ++s) single.step(paper2d, one, one_tangents, 0.01);
      for (std::size_t j = 0; j < k; ++j)
        for (std::size_t i = 0; i < 2; ++i) {
          CHECK(one_tangents.q(j)[i] == all_tangents.q(b * k + j)[i]);
          CHECK(one_tangents.p(j)[i] == all_tangents.p(b * k + j)[i]);
        }
    }
    // Save after 3 steps, restore into a fresh integrator, renormalise, and go on: bit for bit the uninterrupted run.
    TangentIntegrator restored(spec, k);
    restored.restore_state(batch.save_state(all));
    auto x1 = all, t1 = all_tangents, x2 = all, t2 = all_tangents;
    for (std::size_t b = 0; b < 3; ++b) {
      std::array<double, 4> ignored{};
      orthonormalize_state(t1, k, b, ignored);
      orthonormalize_state(t2, k, b, ignored);
    }
    batch.step(paper2d, x1, t1, 0.01);
    restored.step(paper2d, x2, t2, 0.01);
    CHECK(t1.q()[0] == t2.q()[0]);
    CHECK(std::equal(t1.q().begin(), t1.q().end(), t2.q().begin()));
    CHECK(std::equal(t1.p().begin(), t1.p().end(), t2.p().begin()));
    // Retiring the middle state leaves the others' private state aligned: the next step of the two is theirs.
    TangentIntegrator compacted = batch;
    compacted.compact({false, true, false});
    PhaseSpaceBatch x3(2, 2), t3(2, 2 * k);
    for (std::size_t slot = 0, b = 0; b < 3; ++b) {
      if (b == 1) continue;
      std::copy(x1.q(b).begin(), x1.q(b).end(), x3.q(slot).begin());
      std::copy(x1.p(b).begin(), x1.p(b).end(), x3.p(slot).begin());
      for (std::size_t j = 0; j < k; ++j) {
        std::copy(t1.q(b * k + j).begin(), t1.q(b * k + j).end(), t3.q(slot * k + j).begin());
        std::copy(t1.p(b * k + j).begin(), t1.p(b * k + j).end(), t3.p(slot * k + j).begin());
      }
      ++slot;
    }
    batch.step(paper2d, x1, t1, 0.01);
    compacted.step(paper2d, x3, t3, 0.01);
    CHECK(std::equal(t3.q().begin(), t3.q().begin() + 2 * k, t1.q().begin()));
    CHECK(std::equal(t3.q().begin() + 2 * k, t3.q().end(), t1.q().begin() + 4 * k));
  }
}

namespace {

// The Lyapunov records of one state after `time` of steps dt with k = 4 vectors (renormalised every step).
LyapunovRecord spectrum(const Paper2DModel& model, const IntegratorSpec& spec, std::vector<double> q,
                        std::vector<double> p, double dt, double time) {
  auto x = PhaseSpaceBatch::single(q, p);
  auto tangents = testing::identity_tangents(2);
  TangentIntegrator integrator(spec, 4);
  LyapunovExponents exponents(4, 1);
  std::vector<LyapunovRecord> records(1);
  std::vector<double> growth(1);
  exponents.start(tangents, records);
  const long steps = std::lround(time / dt);
  for (long s = 0; s < steps; ++s) {
    integrator.step(model, x, tangents, dt);
    exponents.after_step(tangents, records, dt, growth);
  }
  return records[0];
}

}  // namespace

TEST_CASE("the full Lyapunov spectrum of a symplectic scheme sums to zero within 1e-9 at t = 20") {
  const auto paper2d = Paper2DModel::from_json(R"({"coupling": 0.2})");
  for (int stages : {1, 3}) {
    const IntegratorSpec gauss{"gauss", GaussOptions{stages}};
    CAPTURE(name_of(gauss));
    const LyapunovRecord record = spectrum(paper2d, gauss, {0.5, 0.0}, {0.0, 2.5}, 0.005, 20.0);
    double sum = 0.0;
    for (std::size_t j = 0; j < 4; ++j) sum += record.exponent(j);
    CAPTURE(sum);
    CHECK(record.exponent(0) > 0.5);  // chaotic (about 1.3)
    CHECK(std::abs(sum) < 1e-9);      // measured 3e-15
  }
}

TEST_CASE("tao's tangent map gives Gauss's leading exponent on a chaotic orbit (the projection of its copies)") {
  // Tao's map on (q, p) is not symplectic: its spectrum does not sum to zero (the smallest exponent takes up the
  // copies' part), but the largest exponent is that of the flow.
  const auto paper2d = Paper2DModel::from_json(R"({"coupling": 0.2})");
  const IntegratorSpec gauss{"gauss", GaussOptions{3}};
  const IntegratorSpec tao{"tao", TaoOptions{Fraction(4)}};
  const double reference = spectrum(paper2d, gauss, {-0.75, 0.3}, {-1.5, 0.2}, 0.005, 10.0).exponent(0);
  const double tao_exponent = spectrum(paper2d, tao, {-0.75, 0.3}, {-1.5, 0.2}, 0.005, 10.0).exponent(0);
  CAPTURE(reference);
  CAPTURE(tao_exponent);
  CHECK(std::abs(tao_exponent - reference) < 1e-4 * reference);  // measured 3e-5 relative
}

}  // namespace test_comparator_tangent_maps
