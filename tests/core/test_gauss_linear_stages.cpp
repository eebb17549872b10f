// The direct solve of Gauss-Legendre's linear stages (core/src/tangent/gauss_linear_stages.cpp) at every size it
// takes (s = 1 .. 8 stages, d = 2n components, 2ns <= 32), against the same equations solved by Eigen's LU: random
// Jacobians, 1 and 3 vectors, each vector's result independent of the others, several states solved together each
// bit for bit as alone (a singular one among them named alone); sizes it does not take are refused.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/tangent/gauss_linear_stages.hpp"

namespace test_gauss_linear_stages {

namespace {

// dz' = dz + dt sum_i b_i J_i (dz + dZ_i), dZ from (I - dt (A (x) I) diag(J_j)) dZ = dt (A (x) I) (J_j dz)_j.
Eigen::VectorXd expected(const nonsep::GaussLegendreTableau& tableau, double dt, const std::vector<double>& jacobians,
                         std::size_t d, const Eigen::VectorXd& dz) {
  const std::size_t s = static_cast<std::size_t>(tableau.stages), m = s * d;
  const auto J = [&](std::size_t j) {
    return Eigen::Map<const Eigen::MatrixXd>(jacobians.data() + j * d * d, static_cast<Eigen::Index>(d),
                                             static_cast<Eigen::Index>(d));
  };
  const auto e = [](std::size_t i) { return static_cast<Eigen::Index>(i); };
  Eigen::MatrixXd system = Eigen::MatrixXd::Identity(e(m), e(m));
  Eigen::VectorXd right = Eigen::VectorXd::Zero(e(m));
  for (std::size_t i = 0; i < s; ++i)
    for (std::size_t j = 0; j < s; ++j) {
      const double weight = dt * tableau.a[i * s + j];
      system.block(e(i * d), e(j * d), e(d), e(d)) -= weight * J(j);
      right.segment(e(i * d), e(d)) += weight * J(j) * dz;
    }
  const Eigen::VectorXd dZ = system.partialPivLu().solve(right);
  Eigen::VectorXd next = dz;
  for (std::size_t i = 0; i < s; ++i) next += dt * tableau.b[i] * J(i) * (dz + dZ.segment(e(i * d), e(d)));
  return next;
}

}  // namespace

TEST_CASE("Gauss linear stages: every size solved directly agrees with Eigen's LU, each vector on its own") {
  std::mt19937_64 random(20260);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int sizes = 0;
  for (int s = 1; s <= nonsep::GaussLegendreTableau::max_stages; ++s)
    for (std::size_t d = 2; static_cast<std::size_t>(s) * d <= 32; d += 2) {
      const auto tableau = nonsep::GaussLegendreTableau::for_stages(s);
      const double dt = 0.1;
      std::vector<double> jacobians(static_cast<std::size_t>(s) * d * d);
      for (double& x : jacobians) x = uniform(random);
      for (const std::size_t k : {std::size_t{1}, std::size_t{3}}) {
        std::vector<double> vectors(k * d);
        for (double& x : vectors) x = uniform(random);
        const std::vector<double> start = vectors;
        REQUIRE(nonsep::map_by_linear_stages(tableau, dt, jacobians, d, vectors, k));
        for (std::size_t v = 0; v < k; ++v) {
          const Eigen::VectorXd dz =
              Eigen::Map<const Eigen::VectorXd>(start.data() + v * d, static_cast<Eigen::Index>(d));
          const Eigen::VectorXd want = expected(tableau, dt, jacobians, d, dz);
          std::vector<double> alone(start.begin() + static_cast<std::ptrdiff_t>(v * d),
                                    start.begin() + static_cast<std::ptrdiff_t>((v + 1) * d));
          REQUIRE(nonsep::map_by_linear_stages(tableau, dt, jacobians, d, alone, 1));
          for (std::size_t c = 0; c < d; ++c) {
            CAPTURE(s);
            CAPTURE(d);
            CAPTURE(k);
            CHECK(std::abs(vectors[v * d + c] - want(static_cast<Eigen::Index>(c))) <= 1e-12 * (1.0 + want.norm()));
            CHECK(vectors[v * d + c] == alone[c]);  // batch equals single, bit for bit
          }
        }
      }
      ++sizes;
    }
  CHECK(sizes == 16 + 8 + 5 + 4 + 3 + 2 + 2 + 2);
}

TEST_CASE("Gauss linear stages: states solved together give each state's numbers alone, a singular one named") {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const std::size_t lanes = nonsep::linear_stage_lanes;
  for (const int s : {1, 3, 4})
    for (const std::size_t d : {std::size_t{2}, std::size_t{4}, std::size_t{8}}) {
      if (static_cast<std::size_t>(s) * d > 32) continue;
      const auto tableau = nonsep::GaussLegendreTableau::for_stages(s);
      const double dt = 0.3;
      const std::size_t k = 2, block = static_cast<std::size_t>(s) * d * d;
      for (std::size_t states = 1; states <= lanes; ++states) {
        std::vector<double> jacobians(states * block), vectors(states * k * d);
        for (double& x : jacobians) x = uniform(random);
        for (double& x : vectors) x = uniform(random);
        const std::size_t singular = states - 1;  // the last state's Jacobians not finite
        if (states > 1) jacobians[singular * block + 1] = std::numeric_limits<double>::infinity();
        std::vector<double> together = vectors;
        const unsigned failed = nonsep::map_by_linear_stages(tableau, dt, jacobians, d, together, k, states);
        CAPTURE(s);
        CAPTURE(d);
        CAPTURE(states);
        CHECK(failed == (states > 1 ? 1u << singular : 0u));
        for (std::size_t b = 0; b < states; ++b) {
          if (states > 1 && b == singular) continue;
          std::vector<double> alone(vectors.begin() + static_cast<std::ptrdiff_t>(b * k * d),
                                    vectors.begin() + static_cast<std::ptrdiff_t>((b + 1) * k * d));
          const std::span<const double> own(jacobians.data() + b * block, block);
          REQUIRE(nonsep::map_by_linear_stages(tableau, dt, own, d, alone, k));
          for (std::size_t c = 0; c < k * d; ++c) CHECK(together[b * k * d + c] == alone[c]);
        }
      }
      std::vector<double> jacobians((lanes + 1) * block, 0.0), vectors((lanes + 1) * k * d, 0.0);
      CHECK_THROWS_AS(nonsep::map_by_linear_stages(tableau, dt, jacobians, d, vectors, k, lanes + 1),
                      nonsep::InvalidArgument);
      CHECK_THROWS_AS(
          nonsep::map_by_linear_stages(tableau, dt, std::span<const double>(jacobians).first(block), d, vectors, k, 2),
          nonsep::InvalidArgument);  // the spans of one state, two asked for
    }
}

TEST_CASE("Gauss linear stages: a singular system gives false, sizes beyond the direct solve are refused") {
  const auto tableau = nonsep::GaussLegendreTableau::for_stages(1);  // I - dt a J: singular for J = 1/(dt a) I
  const double dt = 0.5;
  const double inverse = 1.0 / (dt * tableau.a[0]);
  std::vector<double> jacobians = {inverse, 0.0, 0.0, inverse};
  std::vector<double> vectors = {1.0, 1.0};
  CHECK_FALSE(nonsep::map_by_linear_stages(tableau, dt, jacobians, 2, vectors, 1));
  const auto three = nonsep::GaussLegendreTableau::for_stages(3);
  std::vector<double> big(3 * 12 * 12, 0.0), vector(12, 0.0);
  CHECK_THROWS_AS(nonsep::map_by_linear_stages(three, dt, big, 12, vector, 1), nonsep::InvalidArgument);  // 2ns = 36
  std::vector<double> odd(3 * 3 * 3, 0.0), odd_vector(3, 0.0);
  CHECK_THROWS_AS(nonsep::map_by_linear_stages(three, dt, odd, 3, odd_vector, 1), nonsep::InvalidArgument);
}

}  // namespace test_gauss_linear_stages
