// SALI and GALI from the triangular factors of the Lyapunov vectors' orthonormalisations (alignment_indices.hpp)
// against the indices computed from the deviation vectors themselves (Eigen's SVD of the unit vectors), their
// exact decay rates under a linear map with a known spectrum, and what the factors and the skipped MEGNO logarithm
// leave unchanged in LyapunovExponents.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <vector>

#include "nonsep/core/analysis/alignment_indices.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "support/models.hpp"

namespace test_alignment_indices {

using namespace nonsep;

namespace {

constexpr std::size_t n = 2, k = 4;  // four vectors of R^4: GALI_2 .. GALI_4

// The map x -> A x with A = B diag(growth) B^-1: non-normal, Lyapunov exponents ln(growth) per step.
const std::array<double, 4> growth{1.3, 1.1, 0.95, 0.7};
Eigen::Matrix4d linear_map() {
  Eigen::Matrix4d b;
  b << 1.0, 0.4, -0.3, 0.2, 0.1, 1.0, 0.5, -0.4, -0.2, 0.3, 1.0, 0.6, 0.5, -0.1, 0.2, 1.0;
  return b * Eigen::Vector4d(growth[0], growth[1], growth[2], growth[3]).asDiagonal() * b.inverse();
}

Eigen::Matrix4d as_matrix(const PhaseSpaceBatch& tangents) {
  Eigen::Matrix4d m;
  for (std::size_t j = 0; j < k; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = static_cast<Eigen::Index>(j), r = static_cast<Eigen::Index>(i);
      m(r, c) = tangents.q(j)[i], m(r + n, c) = tangents.p(j)[i];
    }
  return m;
}
void from_matrix(const Eigen::Matrix4d& m, PhaseSpaceBatch& tangents) {
  for (std::size_t j = 0; j < k; ++j)
    for (std::size_t i = 0; i < n; ++i) {
      const auto c = static_cast<Eigen::Index>(j), r = static_cast<Eigen::Index>(i);
      tangents.q(j)[i] = m(r, c), tangents.p(j)[i] = m(r + n, c);
    }
}

// GALI_j and SALI of the columns of w, from the definitions: the product of the singular values of the unit
// vectors, and min(|u1 + u2|, |u1 - u2|).
double gali_of(const Eigen::Matrix4d& w, Eigen::Index j) {
  const Eigen::MatrixXd u = w.leftCols(j).colwise().normalized();
  return Eigen::JacobiSVD<Eigen::MatrixXd>(u).singularValues().prod();
}
double sali_of(const Eigen::Matrix4d& w) {
  const Eigen::Vector4d u1 = w.col(0).normalized(), u2 = w.col(1).normalized();
  return std::min((u1 + u2).norm(), (u1 - u2).norm());
}

// One state: its vectors under the map, renormalised every 3 steps, with the factors of SALI and GALI.
struct LinearRun {
  Eigen::Matrix4d a = linear_map();
  PhaseSpaceBatch tangents{n, k};
  LyapunovExponents lyapunov{k, 3};
  AlignmentIndices indices{k};
  std::array<LyapunovRecord, 1> record{};
  std::vector<double> factor = std::vector<double>(AlignmentIndices::factor_size(k));
  Eigen::Matrix4d start;

  LinearRun() {
    Eigen::Matrix4d w0;
    w0 << 1.0, 0.2, 0.0, 0.3, 0.5, 1.0, 0.1, 0.0, -0.3, 0.0, 1.0, 0.2, 0.2, 0.4, 0.0, 1.0;
    from_matrix(w0, tangents);
    lyapunov.start(tangents, record);
    indices.start(factor);
    start = as_matrix(tangents);  // orthonormal: the deviation vectors at t = 0
  }
  void step() {
    from_matrix(a * as_matrix(tangents), tangents);
    lyapunov.after_step(tangents, record, 1.0, {}, factor);
  }
};

}  // namespace

TEST_CASE("SALI and GALI_j from the factors are those of the unit deviation vectors (SVD), at every renormalisation") {
  LinearRun run;
  CHECK(AlignmentIndices::gali(run.factor, 4) == 1.0);
  Eigen::Matrix4d w = run.start;  // the deviation vectors, never renormalised
  int compared = 0;
  for (int s = 1; s <= 30; ++s) {
    run.step();
    w = run.a * w;
    if (s % 3 != 0) continue;
    CAPTURE(s);
    for (Eigen::Index j = 2; j <= 4; ++j) {
      const double direct = gali_of(w, j);
      CAPTURE(j);
      // The SVD of unit vectors resolves a volume to about 1e-16 absolutely: compare while that is 1e-7 relative.
      if (direct < 1e-9) continue;
      CHECK(AlignmentIndices::gali(run.factor, static_cast<std::size_t>(j)) == doctest::Approx(direct).epsilon(1e-7));
      ++compared;
    }
    CHECK(AlignmentIndices::sali(run.factor) == doctest::Approx(sali_of(w)).epsilon(1e-7));
  }
  CHECK(compared >= 20);
}

TEST_CASE("under a linear map GALI_j decays at exactly the rate sum_{i<=j} (l_1 - l_i), far below round-off") {
  LinearRun run;
  std::array<double, 5> log_gali_200{};
  for (int s = 1; s <= 300; ++s) {
    run.step();
    if (s == 201)  // at a renormalisation (3 | 201)
      for (std::size_t j = 2; j <= 4; ++j) log_gali_200[j] = std::log(AlignmentIndices::gali(run.factor, j));
  }
  for (std::size_t j = 2; j <= 4; ++j) {
    double law = 0.0;
    for (std::size_t i = 1; i < j; ++i) law += std::log(growth[0]) - std::log(growth[i]);
    const double gali = AlignmentIndices::gali(run.factor, j), rate = -(std::log(gali) - log_gali_200[j]) / 99.0;
    CAPTURE(j);
    CAPTURE(gali);
    CHECK(rate == doctest::Approx(law).epsilon(1e-9));
    CHECK(gali > 0.0);
  }
  CHECK(AlignmentIndices::gali(run.factor, 4) < 1e-100);  // GALI_4 ~ exp(-1.10 t): 1e-143 at t = 300
  // SALI ~ sqrt(2) GALI_2 once the two vectors are nearly parallel.
  CHECK(AlignmentIndices::sali(run.factor) ==
        doctest::Approx(std::sqrt(2.0) * AlignmentIndices::gali(run.factor, 2)).epsilon(1e-12));
}

TEST_CASE("the factors and the skipped MEGNO logarithm leave the exponents bit for bit") {
  using nonsep::testing::Paper2D;
  const IntegratorSpec mpe4{"mpe", ChinOptions{Fraction(4)}};
  std::array<TangentIntegrator, 3> integrators{TangentIntegrator(mpe4), TangentIntegrator(mpe4),
                                               TangentIntegrator(mpe4)};
  PhaseSpaceBatch x_first = PhaseSpaceBatch::single(std::vector<double>{-0.75, 0.3}, std::vector<double>{-1.5, 0.2});
  PhaseSpaceBatch tangents_first(2, 3);
  for (std::size_t i = 0; i < tangents_first.size(); ++i) {
    tangents_first.q()[i] = std::sin(1.0 + static_cast<double>(i));
    tangents_first.p()[i] = std::cos(3.0 * static_cast<double>(i));
  }
  // Three runs of the same orbit: with MEGNO's growth, without anything, with the SALI/GALI factors.
  std::array<PhaseSpaceBatch, 3> x{x_first, x_first, x_first}, tangents{tangents_first, tangents_first, tangents_first};
  std::array<std::array<LyapunovRecord, 1>, 3> records{};
  LyapunovExponents lyapunov(3, 7);
  std::array<double, 1> growth{};
  std::vector<double> factor(AlignmentIndices::factor_size(3));
  AlignmentIndices(3).start(factor);
  for (std::size_t r = 0; r < 3; ++r) lyapunov.start(tangents[r], records[r]);
  for (int s = 0; s < 200; ++s)
    for (std::size_t r = 0; r < 3; ++r) {
      integrators[r].step(Paper2D{}, x[r], tangents[r], 0.002);
      if (r == 0) lyapunov.after_step(tangents[r], records[r], 0.002, growth);
      if (r == 1) lyapunov.after_step(tangents[r], records[r], 0.002);
      if (r == 2) lyapunov.after_step(tangents[r], records[r], 0.002, {}, factor);
    }
  for (std::size_t r = 1; r < 3; ++r) {
    CHECK(tangents[r] == tangents[0]);
    CHECK(records[r][0].log_stretch == records[0][0].log_stretch);
    CHECK(records[r][0].time == records[0][0].time);
    CHECK(records[r][0].log_norm_first == 0.0);  // 200 = 28 * 7 + 4: MEGNO's run has ln |v_1| != 0 there
  }
  CHECK(records[0][0].log_norm_first != 0.0);
  CHECK(AlignmentIndices::gali(factor, 3) < AlignmentIndices::gali(factor, 2));
  PhaseSpaceBatch one_vector(2, 1);
  one_vector.q()[0] = 1.0;
  CHECK_THROWS_WITH_AS(LyapunovExponents(1, 1).after_step(one_vector, records[0], 0.002, {}, factor),
                       doctest::Contains("at least 2 tangent vectors"), InvalidArgument);
  std::vector<double> wrong(5);
  CHECK_THROWS_WITH_AS(lyapunov.after_step(tangents[0], records[0], 0.002, {}, wrong), doctest::Contains("expected 6"),
                       InvalidArgument);
}

}  // namespace test_alignment_indices
