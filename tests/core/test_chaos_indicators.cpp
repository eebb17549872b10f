// Lyapunov exponents and MEGNO over the tangent maps: the algorithms on input with known answers (QR, synthetic
// growth), the records restored bit for bit, and the exact sum of the spectrum of a symplectic map. Whole orbits
// against the reference are in test_chaos_against_reference.cpp.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>
#include <type_traits>
#include <vector>

#include "nonsep/core.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/analysis/megno.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "support/models.hpp"

namespace test_chaos_indicators {

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
  MegnoIndicator megno;
  std::vector<double> megno_state = std::vector<double>(MegnoIndicator::state_numbers);
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
    megno.start(megno_state);
  }
  void step(double dt) {
    integrator.step(model, x, tangents, dt);
    lyapunov.after_step(tangents, lyapunov_record, dt, growth);
    megno.after_step(megno_state, growth[0], dt);
  }
  const LyapunovRecord& record() const { return lyapunov_record[0]; }
  double mean_y() const {
    std::array<double, 2> out{};
    megno.values(megno_state, record(), out);
    return out[1];
  }
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

namespace {

// The MEGNO indicator fed with L(t_k) = ln |w(t_k)| of a known function (growth = L_k - L_{k-1}), N steps of h.
struct SyntheticMegno {
  MegnoIndicator megno;
  std::vector<double> state = std::vector<double>(MegnoIndicator::state_numbers);
  std::array<double, 2> out{};
  template <class L>
  SyntheticMegno(L&& log_norm, double h, int steps) {
    megno.start(state);
    for (int k = 1; k <= steps; ++k) megno.after_step(state, log_norm(k * h) - log_norm((k - 1) * h), h);
    megno.values(state, LyapunovRecord{}, out);
  }
  double y() const { return out[0]; }
  double mean_y() const { return out[1]; }
};

}  // namespace

TEST_CASE("MEGNO of synthetic growth: linear growth gives 2, exponential growth lambda t and lambda t / 2 exactly") {
  // ln |w| = ln(1 + t): I1 = (1 + t) ln(1 + t) - t, I2 = I1 + int_0^t ln(1 + s)/s ds - t, so Y = 2 - 2 ln(1 + t)/t and
  // <Y> tend to 2 like ln t / t and ln^2 t / t.
  const double t = 2000.0;
  const SyntheticMegno linear([](double s) { return std::log1p(s); }, 0.1, 20000);
  const double dilog = boost::math::quadrature::gauss_kronrod<double, 61>::integrate(
      [](double s) { return s == 0.0 ? 1.0 : std::log1p(s) / s; }, 0.0, t, 20, 1e-15);
  const double i1 = (1.0 + t) * std::log1p(t) - t, i2 = i1 + dilog - t;
  CHECK(linear.y() == doctest::Approx(2.0 - 2.0 * std::log1p(t) / t).epsilon(1e-12));
  CHECK(linear.mean_y() == doctest::Approx(2.0 * (i1 - i2) / t).epsilon(1e-10));
  CHECK(linear.mean_y() == doctest::Approx(2.0).epsilon(0.05));
  // ln |w| = lambda t is a polynomial: the quadratures are exact at every step, the first ones included.
  for (int steps : {1, 2, 5, 8, 9, 20, 2000}) {
    CAPTURE(steps);
    const SyntheticMegno exponential([](double t) { return 0.3 * t; }, 0.1, steps);
    CHECK(exponential.y() == doctest::Approx(0.3 * 0.1 * steps).epsilon(1e-13));
    CHECK(exponential.mean_y() == doctest::Approx(0.3 * 0.1 * steps / 2.0).epsilon(1e-13));
  }
}

TEST_CASE("MEGNO's quadratures are of order 10: ln |w| = lambda t + a sin(omega t) against its exact Y and <Y>") {
  // I1 = lambda t^2 / 2 + (a / omega)(1 - cos omega t), I2 = lambda t^2 / 4 + (a / omega) Cin(omega t),
  // Cin(x) = int_0^x (1 - cos u) / u du; Y = 2 L - 2 I1 / t, <Y> = 2 (I1 - I2) / t.
  const double lambda = 0.2, a = 0.5, omega = 1.3, t = 10.0;
  const auto log_norm = [&](double s) { return lambda * s + a * std::sin(omega * s); };
  const double cin = boost::math::quadrature::gauss_kronrod<double, 61>::integrate(
      [](double u) { return u == 0.0 ? 0.0 : (1.0 - std::cos(u)) / u; }, 0.0, omega * t, 15, 1e-15);
  const double i1 = lambda * t * t / 2.0 + a / omega * (1.0 - std::cos(omega * t));
  const double i2 = lambda * t * t / 4.0 + a / omega * cin;
  const double y = 2.0 * log_norm(t) - 2.0 * i1 / t, mean_y = 2.0 * (i1 - i2) / t;
  std::vector<double> y_errors, mean_errors;
  for (int steps : {20, 40, 80, 160}) {
    const SyntheticMegno run(log_norm, t / steps, steps);
    y_errors.push_back(std::abs(run.y() - y));
    mean_errors.push_back(std::abs(run.mean_y() - mean_y));
  }
  for (std::size_t i = 0; i + 2 < y_errors.size(); ++i) {  // the last step reaches round-off
    const double y_order = std::log2(y_errors[i] / y_errors[i + 1]),
                 mean_order = std::log2(mean_errors[i] / mean_errors[i + 1]);
    MESSAGE("h = " << t / (20 << i) << ": |Y error| " << y_errors[i] << " -> " << y_errors[i + 1] << " (order "
                   << y_order << "), |<Y> error| " << mean_errors[i] << " -> " << mean_errors[i + 1] << " (order "
                   << mean_order << ")");
    CHECK(y_order > 9.0);
    CHECK(mean_order > 9.0);
  }
  CHECK(mean_errors.back() < 1e-12);
}

TEST_CASE("restoring the records and vectors of a run continues it bit for bit") {
  const std::vector<double> delta{1, 0.5, -0.3, 0.7, 0.2, -1, 0.4, 0.1};  // k = 2
  const double dt = opaque(0.002);
  IndicatorRun run(Paper2D{}, mpe4, {-0.75, 0.3}, {-1.5, 0.2}, delta, 7);
  for (int s = 0; s < 100; ++s) run.step(dt);
  // A checkpoint: the state, the vectors and the trivially copyable records, as bytes.
  static_assert(std::is_trivially_copyable_v<LyapunovRecord>);
  const auto x = run.x, tangents = run.tangents;
  const auto records = run.lyapunov_record;
  const auto megno = run.megno_state;
  for (int s = 0; s < 100; ++s) run.step(dt);
  IndicatorRun resumed(Paper2D{}, mpe4, {0, 0}, {1, 1}, delta, 7);
  resumed.x = x, resumed.tangents = tangents, resumed.lyapunov_record = records, resumed.megno_state = megno;
  for (int s = 0; s < 100; ++s) resumed.step(dt);
  CHECK(resumed.x == run.x);
  CHECK(resumed.tangents == run.tangents);
  CHECK(resumed.lyapunov_record == run.lyapunov_record);
  CHECK(resumed.megno_state == run.megno_state);
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

}  // namespace test_chaos_indicators
