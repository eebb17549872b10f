#pragma once
// SALI (Skokos, J. Phys. A 34, 10029 (2001)) and GALI_j (Skokos, Bountis and Antonopoulos, Physica D 231, 30
// (2007)) of the k tangent vectors that LyapunovExponents follows, without a second set of vectors.
//
// The indices. Deviation vectors w_1 .. w_k start orthonormal and follow the tangent map alone, W(t) = M(t) W(0);
// with the unit vectors u_j = w_j / |w_j| and U_j = [u_1 .. u_j] (2n x j),
//   SALI(t)   = min(|u_1 + u_2|, |u_1 - u_2|),
//   GALI_j(t) = |u_1 ^ u_2 ^ ... ^ u_j| = the product of the j singular values of U_j,   j = 2 .. k.
// Both -> 0 exponentially on a chaotic orbit, GALI_j ~ exp(-[(l_1 - l_2) + ... + (l_1 - l_j)] t) (l the Lyapunov
// spectrum, SALI like GALI_2); on an N-torus GALI_j stays near a constant for j <= N and decays like
// t^(-2(j - N)) for N < j <= 2N, and SALI stays away from 0.
//
// How. LyapunovExponents keeps orthonormal vectors Q instead of W: at each orthonormalisation the mapped vectors
// are V = Q' R' (modified Gram-Schmidt, R' upper triangular with R'_jj > 0) and Q <- Q'. So W = Q C at all times,
// with C = R'_r ... R'_1 upper triangular (C = I at the start). Scaling the columns of C scales the w_j and changes
// neither index, so a state carries C with unit columns and, at each orthonormalisation,
//   C <- R' C, then each column divided by its Euclidean norm.
// Then U = Q C with Q orthonormal: U_j's singular values are those of C's leading j x j block, which is triangular,
//   GALI_j = det C[0..j) = C_00 C_11 ... C_(j-1)(j-1),   and with u_1 . u_2 = C_01 (column 0 of C is e_1),
//   SALI = sqrt(2 - 2 |C_01|) = C_11 sqrt(2 / (1 + |C_01|))   (C_01^2 + C_11^2 = 1; no cancellation).
// Computed from the vectors themselves, both indices would stop near 1e-16 once the vectors of a chaotic orbit are
// parallel to round-off; here the diagonal entries are multiplied and follow the decay further (down to the
// smallest double, then 0). Values are those at the last orthonormalisation, like LyapunovRecord::exponent.
//
// Layout: one factor per state, factor_size(k) = k(k+1)/2 numbers, the upper triangle column by column (column j
// at offset j(j+1)/2, rows 0 .. j); the factors of a batch one after the other. R (from orthonormalize_state) is
// k x k row-major: R_ij at i*k + j. Trivially restored: a checkpoint stores the factors as numbers.
//
// LyapunovExponents::after_step calls update() when it is given the factors. Errors: InvalidArgument for k < 2
// or spans of the wrong size.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/core/base/error.hpp"

namespace nonsep {

class AlignmentIndices {
 public:
  explicit AlignmentIndices(std::size_t k) : k_(k) {
    if (k < 2) throw InvalidArgument("SALI and GALI need at least 2 tangent vectors (found " + std::to_string(k) + ")");
  }

  static constexpr std::size_t factor_size(std::size_t k) { return k * (k + 1) / 2; }
  std::size_t vectors() const { return k_; }
  std::size_t factor_size() const { return factor_size(k_); }

  // Every factor of `factors` (states one after the other) to the identity: the vectors just orthonormalised.
  void start(std::span<double> factors) const {
    check_size(factors.size() % factor_size() == 0, factors.size(), "a multiple of");
    for (std::size_t first = 0; first < factors.size(); first += factor_size())
      for (std::size_t j = 0; j < k_; ++j)
        for (std::size_t i = 0; i <= j; ++i) factors[first + entry(i, j)] = i == j ? 1.0 : 0.0;
  }

  // One state's factor after an orthonormalisation whose triangular factor was `r` (k x k, row-major).
  void update(std::span<double> factor, std::span<const double> r) const {
    check_size(factor.size() == factor_size(), factor.size(), "");
    if (r.size() != k_ * k_)
      throw InvalidArgument("the triangular factor R has " + std::to_string(r.size()) + " entries for " +
                            std::to_string(k_) + " vectors (expected " + std::to_string(k_ * k_) + ")");
    // Row i of column j of R C needs rows i .. j of column j of C: in place, rows in increasing order.
    for (std::size_t j = 0; j < k_; ++j) {
      double squared = 0.0;
      for (std::size_t i = 0; i <= j; ++i) {
        double sum = 0.0;
        for (std::size_t l = i; l <= j; ++l) sum += r[i * k_ + l] * factor[entry(l, j)];
        factor[entry(i, j)] = sum;
        squared += sum * sum;
      }
      const double inverse = 1.0 / std::sqrt(squared);
      for (std::size_t i = 0; i <= j; ++i) factor[entry(i, j)] *= inverse;
    }
  }

  // SALI of the first two vectors from a state's factor.
  static double sali(std::span<const double> factor) {
    const double c01 = factor[entry(0, 1)], c11 = factor[entry(1, 1)];
    return c11 * std::sqrt(2.0 / (1.0 + std::abs(c01)));
  }
  // GALI_j of the first j vectors (2 <= j <= k) from a state's factor.
  static double gali(std::span<const double> factor, std::size_t j) {
    double volume = 1.0;
    for (std::size_t i = 0; i < j; ++i) volume *= factor[entry(i, i)];
    return volume;
  }

  // The index of C_ij (i <= j) in a factor.
  static constexpr std::size_t entry(std::size_t i, std::size_t j) { return j * (j + 1) / 2 + i; }

 private:
  void check_size(bool valid, std::size_t found, const std::string& relation) const {
    if (!valid)
      throw InvalidArgument("SALI/GALI factors: " + std::to_string(found) + " numbers where " + relation + " " +
                            std::to_string(factor_size()) + " (k(k+1)/2 for k = " + std::to_string(k_) +
                            ") are expected");
  }

  std::size_t k_;
};

// SALI and GALI as indicators (indicator.hpp): SALI (columns: sali) from the factor of the first 2 vectors, GALI
// (columns gali2 .. gali<k>) from that of the first k; state: the factor. A factor of the first j vectors is the
// leading part of that of more vectors, bit for bit (column j of C needs rows 0 .. j of R only), so each keeps its own.
class AlignmentIndicator final : public Indicator {
 public:
  static AlignmentIndicator sali() { return AlignmentIndicator(0); }
  static AlignmentIndicator gali(std::size_t k) { return AlignmentIndicator(k); }

  std::string name() const override { return gali_ == 0 ? "sali" : "gali"; }
  IndicatorNeeds needs() const override {
    return {.tangent_vectors = indices_.vectors(),
            .orthonormalization_factors = true,
            .state_size = indices_.factor_size()};
  }
  std::vector<std::string> columns() const override {
    if (gali_ == 0) return {"sali"};
    std::vector<std::string> names;
    for (std::size_t j = 2; j <= gali_; ++j) names.push_back("gali" + std::to_string(j));
    return names;
  }
  std::string description() const override {
    return gali_ == 0 ? "trajectories.csv sali, of the first two vectors"
                      : "trajectories.csv gali2 .. gali" + std::to_string(gali_) + ", GALI_j of the first j vectors";
  }
  std::vector<std::pair<std::string, std::size_t>> settings() const override {
    if (gali_ == 0) return {};
    return {{"vectors", gali_}};
  }

  void start(std::span<double> state) const override { indices_.start(state); }
  // R's leading block of this indicator's vectors.
  void after_orthonormalization(std::span<double> state, std::span<const double> r, std::size_t k) const override {
    const std::size_t own = indices_.vectors();
    std::array<double, LyapunovRecord::max_exponents * LyapunovRecord::max_exponents> leading;  // written before read
    for (std::size_t i = 0; i < own; ++i)
      for (std::size_t j = 0; j < own; ++j) leading[i * own + j] = r[i * k + j];
    indices_.update(state, std::span<const double>(leading.data(), own * own));
  }
  void values(std::span<const double> state, const LyapunovRecord&, std::span<double> out) const override {
    if (gali_ == 0) {
      out[0] = AlignmentIndices::sali(state);
      return;
    }
    for (std::size_t j = 2; j <= gali_; ++j) out[j - 2] = AlignmentIndices::gali(state, j);
  }

 private:
  explicit AlignmentIndicator(std::size_t gali) : gali_(gali), indices_(std::max<std::size_t>(2, gali)) {}
  std::size_t gali_;  // 0: SALI
  AlignmentIndices indices_;
};

}  // namespace nonsep
