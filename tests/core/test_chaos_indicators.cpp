// Lyapunov exponents and MEGNO over the tangent maps: the algorithms on input with known answers (QR, synthetic
// growth), the records restored bit for bit, and the exact sum of the spectrum of a symplectic map. Whole orbits
// against the reference are in test_chaos_against_reference.cpp.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <type_traits>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/analysis/megno.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "support/models.hpp"

using namespace nonsep;
using nonsep::testing::Paper2D;

namespace {

// One trajectory with k tangent vectors, stepped by a TangentIntegrator, its Lyapunov and MEGNO records kept.
template <class M>
struct IndicatorRun {
  M model;  // a copy: the tests pass temporaries
  TangentIntegrator integrator;
  LyapunovExponents lyapunov;
  PhaseSpaceBatch x, tangents;
  std::array<LyapunovRecord, 1> lyapunov_record{};
  std::array<MegnoRecord, 1> megno_record{};
  std::array<double, 1> growth{};

  // `delta` holds the k initial vectors one after the other, each (dq, dp).
  IndicatorRun(const M& m, const IntegratorSpec& spec, std::vector<double> q, std::vector<double> p,
               const std::vector<double>& delta, std::size_t renormalize_every)
      : model(m),
        integrator(spec),
        lyapunov(delta.size() / (2 * q.size()), renormalize_every),
        x(PhaseSpaceBatch::single(q, p)),
        tangents(q.size(), delta.size() / (2 * q.size())) {
    const std::size_t n = q.size();
    for (std::size_t j = 0; j < tangents.count(); ++j)
      for (std::size_t i = 0; i < n; ++i) {
        tangents.q(j)[i] = delta[2 * n * j + i];
        tangents.p(j)[i] = delta[2 * n * j + n + i];
      }
    lyapunov.start(tangents, lyapunov_record);
  }
  void step(double dt) {
    integrator.step(model, x, tangents, dt);
    lyapunov.after_step(tangents, lyapunov_record, dt, growth);
    add_megno_step(megno_record, growth, dt);
  }
  const LyapunovRecord& record() const { return lyapunov_record[0]; }
  double mean_y() const { return megno_record[0].mean_y(); }
};

// Order 4, not symplectic: accurate and stable on paper2d's chaotic orbit at dt = 2e-3.
const IntegratorSpec mpe4{"mpe", ChinOptions{Fraction(4)}};

// dt as a value the compiler cannot see (see test_tangent_map.cpp: a literal dt can make std::cbrt differ by an
// ulp between two call sites that the compiler inlines differently).
double opaque(double dt) {
  volatile double value = dt;
  return value;
}

}  // namespace

TEST_CASE("modified Gram-Schmidt gives the Q and |R_jj| of a QR factorisation") {
  PhaseSpaceBatch tangents(2, 2 * 3);  // two states, three vectors of R^4 each
  for (std::size_t i = 0; i < tangents.size(); ++i) {
    tangents.q()[i] = std::sin(1.0 + 3.0 * static_cast<double>(i));
    tangents.p()[i] = std::cos(2.0 + 5.0 * static_cast<double>(i));
  }
  const auto before = tangents;
  for (std::size_t b = 0; b < 2; ++b) {
    std::array<double, 3> log_norms{};
    orthonormalize_state(tangents, 3, b, log_norms);
    Eigen::MatrixXd v(4, 3), q(4, 3);
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t i = 0; i < 2; ++i) {
        const auto c = static_cast<Eigen::Index>(j), r = static_cast<Eigen::Index>(i);
        v(r, c) = before.q(3 * b + j)[i], v(2 + r, c) = before.p(3 * b + j)[i];
        q(r, c) = tangents.q(3 * b + j)[i], q(2 + r, c) = tangents.p(3 * b + j)[i];
      }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(v);
    const Eigen::MatrixXd r = qr.matrixQR().triangularView<Eigen::Upper>();
    for (Eigen::Index j = 0; j < 3; ++j)
      CHECK(log_norms[static_cast<std::size_t>(j)] == doctest::Approx(std::log(std::abs(r(j, j)))).epsilon(1e-13));
    CHECK((q.transpose() * q - Eigen::MatrixXd::Identity(3, 3)).cwiseAbs().maxCoeff() < 1e-14);
    CHECK((q.transpose() * v).triangularView<Eigen::StrictlyLower>().toDenseMatrix().cwiseAbs().maxCoeff() < 1e-14);
  }
}

TEST_CASE("MEGNO of synthetic growth: linear growth gives 2, exponential growth lambda t and lambda t / 2") {
  const double dt = 0.1;
  const int steps = 20000;
  MegnoRecord linear, exponential;
  for (int k = 1; k <= steps; ++k) {
    linear.add_step(std::log((k + 1.0) / k), dt);  // |delta_k| = k + 1
    exponential.add_step(0.3 * dt, dt);            // |delta_k| = exp(0.3 t_k)
  }
  CHECK(linear.y() == doctest::Approx(2.0).epsilon(1e-3));
  CHECK(linear.mean_y() == doctest::Approx(2.0).epsilon(5e-3));
  // Exactly: Y_N = (2/N) sum k lambda dt = lambda dt (N + 1); <Y>_N = (1/N) sum_k lambda dt (k + 1).
  CHECK(exponential.y() == doctest::Approx(0.3 * dt * (steps + 1)).epsilon(1e-12));
  CHECK(exponential.mean_y() == doctest::Approx(0.3 * dt * (steps + 3) / 2.0).epsilon(1e-12));
}

TEST_CASE("restoring the records and vectors of a run continues it bit for bit") {
  const std::vector<double> delta{1, 0.5, -0.3, 0.7, 0.2, -1, 0.4, 0.1};  // k = 2
  const double dt = opaque(0.002);
  IndicatorRun run(Paper2D{}, mpe4, {-0.75, 0.3}, {-1.5, 0.2}, delta, 7);
  for (int s = 0; s < 100; ++s) run.step(dt);
  // A checkpoint: the state, the vectors and the trivially copyable records, as bytes.
  static_assert(std::is_trivially_copyable_v<LyapunovRecord> && std::is_trivially_copyable_v<MegnoRecord>);
  const auto x = run.x, tangents = run.tangents;
  const auto records = run.lyapunov_record;
  const auto megno = run.megno_record;
  for (int s = 0; s < 100; ++s) run.step(dt);
  IndicatorRun resumed(Paper2D{}, mpe4, {0, 0}, {1, 1}, delta, 7);
  resumed.x = x, resumed.tangents = tangents, resumed.lyapunov_record = records, resumed.megno_record = megno;
  for (int s = 0; s < 100; ++s) resumed.step(dt);
  CHECK(resumed.x == run.x);
  CHECK(resumed.tangents == run.tangents);
  CHECK(resumed.lyapunov_record == run.lyapunov_record);
  CHECK(resumed.megno_record == run.megno_record);
  CHECK(run.record().steps == 200);
  CHECK(run.record().time == doctest::Approx(196 * dt).epsilon(1e-12));  // 28 renormalisations of 7 steps
}

TEST_CASE("the full spectrum of a symplectic map sums to zero (det M = 1), and MPE's does not") {
  const std::vector<double> delta{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // k = 2n = 4
  // Triplet of order 2, stable on this chaotic orbit at dt = 1e-3; MPE of order 4 at dt = 4e-3 as the negative
  // control.
  for (const IntegratorSpec& spec :
       {IntegratorSpec{"triplet", ChinOptions{Fraction(2)}}, IntegratorSpec{"mpe", ChinOptions{Fraction(4)}}}) {
    CAPTURE(spec.scheme);
    IndicatorRun run(Paper2D{}, spec, {-0.75, 0.3}, {-1.5, 0.2}, delta, 10);
    const double dt = spec.scheme == "mpe" ? 0.004 : 0.001;
    for (int s = 0; s < static_cast<int>(std::lround(10.0 / dt)); ++s) run.step(dt);
    const auto& r = run.record();
    CAPTURE(r.exponent(0));
    CAPTURE(r.exponent(1));
    CAPTURE(r.exponent(2));
    CAPTURE(r.exponent(3));
    // The sum of ln R_jj is ln |det M|: zero to round-off for a symplectic map. (The finite-time exponents at
    // t = 10 are far from their limits (lambda, 0, 0, -lambda); only their sum is exact.)
    const double sum = r.log_stretch[0] + r.log_stretch[1] + r.log_stretch[2] + r.log_stretch[3];
    MESSAGE(spec.scheme << ": sum of ln R_jj " << sum);
    if (spec.scheme == "triplet")
      CHECK(std::abs(sum) < 1e-11);  // measured 5e-14
    else
      CHECK(std::abs(sum) > 1e-7);               // measured 4e-6
    CHECK(r.exponent(0) + r.exponent(1) > 0.1);  // areas grow: the orbit is chaotic
  }
}
