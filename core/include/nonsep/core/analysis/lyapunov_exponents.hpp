#pragma once
// Finite-time Lyapunov exponents by Benettin et al.'s method (Meccanica 15, 9 (1980)): k tangent vectors follow
// the tangent map of the integrator (tangent_basic_step.hpp and its wrappers); every `renormalize_every` steps
// they are re-orthonormalised by modified Gram-Schmidt (the QR factorisation V = Q R, V <- Q), and ln R_jj is
// added to the sum of vector j. After a time t the estimate of exponent j is that sum divided by t:
//   lambda_j(t) = (1/t) sum_r ln R_jj(r),   lambda_1 >= lambda_2 >= ... for large t.
// k = 1 gives the largest exponent; k = 2n the whole spectrum, which for a symplectic map comes in pairs
// lambda_j = -lambda_{2n+1-j} and sums to zero.
//
// Vectors: the tangent layout of tangent_basic_step.hpp (vector j of state b is entry b*k + j of a
// PhaseSpaceBatch, dq in q(), dp in p()); the inner product is the Euclidean one of R^{2n}, dq.dq' + dp.dp'.
//
// Per-trajectory state: one LyapunovRecord per state, owned by the caller (a checkpoint stores the records and
// the tangent vectors; restoring both bit for bit continues the run bit for bit). The record is trivially
// copyable and holds no pointers. Besides the sums it keeps ln |v_1| since the last orthonormalisation, so that
// after_step() can hand out the step's growth of the first vector, ln(|v_1(t_k)| / |v_1(t_{k-1})|), which
// MEGNO needs (megno.hpp), whether or not the step renormalised; only when asked (a logarithm per state and step).
// SALI and GALI come from the same vectors and the triangular factors of the orthonormalisations
// (alignment_indices.hpp).
//
// Errors: InvalidArgument for k outside 1 .. min(2n, max_exponents), renormalize_every == 0, or spans whose
// sizes disagree with the batch. A tangent vector that has become zero, infinite or NaN (an overflow of the
// state, or k > rank) gives non-finite sums, not an exception: the caller sees NaN exponents.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "nonsep/core/analysis/alignment_indices.hpp"
#include "nonsep/core/analysis/lyapunov_record.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/phase_space_batch.hpp"

namespace nonsep {

// Modified Gram-Schmidt of the k vectors of state b of `tangents` (layout above), in place: afterwards they are
// orthonormal, and log_norms[j] = ln R_jj (the length of vector j after the projections onto vectors 0 .. j-1
// were removed), j < k. When `r` is not empty (k*k numbers) it gets the whole triangular factor of V = Q R,
// row-major (R_ij at i*k + j, zeros below the diagonal), for alignment_indices.hpp.
inline void orthonormalize_state(PhaseSpaceBatch& tangents, std::size_t k, std::size_t b, std::span<double> log_norms,
                                 std::span<double> r = {}) {
  const std::size_t n = tangents.dimension();
  double* q = tangents.q().data() + b * k * n;
  double* p = tangents.p().data() + b * k * n;
  auto dot = [&](std::size_t a, std::size_t c) {
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) sum += q[a * n + i] * q[c * n + i] + p[a * n + i] * p[c * n + i];
    return sum;
  };
  for (std::size_t j = 0; j < k; ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const double projection = dot(i, j);
      if (!r.empty()) r[i * k + j] = projection;
      for (std::size_t m = 0; m < n; ++m) {
        q[j * n + m] -= projection * q[i * n + m];
        p[j * n + m] -= projection * p[i * n + m];
      }
    }
    const double norm = std::sqrt(dot(j, j));
    log_norms[j] = std::log(norm);
    if (!r.empty()) {
      r[j * k + j] = norm;
      for (std::size_t i = j + 1; i < k; ++i) r[i * k + j] = 0.0;
    }
    const double inverse = 1.0 / norm;
    for (std::size_t m = 0; m < n; ++m) {
      q[j * n + m] *= inverse;
      p[j * n + m] *= inverse;
    }
  }
}

class LyapunovExponents {
 public:
  // Called at each orthonormalisation of state b with its triangular factor R (k x k, row-major).
  using OrthonormalizationHook = std::function<void(std::size_t b, std::span<const double> r)>;

  // k vectors per state (1 for the largest exponent), re-orthonormalised every `renormalize_every` steps.
  LyapunovExponents(std::size_t k, std::size_t renormalize_every) : k_(k), renormalize_every_(renormalize_every) {
    if (k == 0 || k > LyapunovRecord::max_exponents)
      throw InvalidArgument("the number of Lyapunov exponents must be between 1 and " +
                            std::to_string(LyapunovRecord::max_exponents) + " (found " + std::to_string(k) + ")");
    if (renormalize_every == 0) throw InvalidArgument("renormalize_every must be at least 1 step (found 0)");
  }

  std::size_t exponents() const { return k_; }
  std::size_t renormalize_every() const { return renormalize_every_; }

  // Orthonormalises the initial tangent vectors (any k linearly independent vectors per state; the first one's
  // direction is kept) and resets the records to time 0.
  void start(PhaseSpaceBatch& tangents, std::span<LyapunovRecord> records) {
    check(tangents, records);
    std::array<double, LyapunovRecord::max_exponents> ignored{};
    for (std::size_t b = 0; b < records.size(); ++b) {
      orthonormalize_state(tangents, k_, b, ignored);
      records[b] = LyapunovRecord{};
    }
  }

  // To be called after each step of dt of the states and their tangent vectors: re-orthonormalises the vectors of
  // the states that reached renormalize_every steps since their last orthonormalisation. Two optional outputs, each
  // either empty (not computed) or sized for every state:
  //   first_growth: records.size() numbers, ln(|v_1| after / |v_1| before) of state b over this step (for MEGNO);
  //     empty: the first vector's norm and logarithm are not computed, and record.log_norm_first stays 0;
  //   alignment: records.size() factors of AlignmentIndices(k) (alignment_indices.hpp), updated with the
  //     triangular factor of each orthonormalisation (k >= 2).
  // The exponents are the same bit for bit whichever outputs are asked for.
  void after_step(PhaseSpaceBatch& tangents, std::span<LyapunovRecord> records, double dt,
                  std::span<double> first_growth, std::span<double> alignment = {}) {
    after_steps(tangents, records, dt, 1, first_growth, alignment);
  }
  // Without first_growth and alignment.
  void after_step(PhaseSpaceBatch& tangents, std::span<LyapunovRecord> records, double dt) {
    after_steps(tangents, records, dt, 1, {}, OrthonormalizationHook());
  }

  // The steps every state can take before one reaches its next orthonormalisation (at least 1; renormalize_every
  // for no state).
  std::uint64_t steps_to_renormalization(std::span<const LyapunovRecord> records) const {
    std::uint64_t steps = renormalize_every_;
    for (const LyapunovRecord& record : records)
      steps = std::min<std::uint64_t>(steps, renormalize_every_ - record.steps_since_renormalization);
    return steps;
  }

  // after_step for `steps` steps of dt taken together (a tangent kernel's run): the same records and vectors bit for
  // bit as `steps` calls of after_step, when no state reaches its orthonormalisation before the last of them
  // (steps <= steps_to_renormalization(records); InvalidArgument otherwise). first_growth, when not empty, requires
  // steps == 1.
  void after_steps(PhaseSpaceBatch& tangents, std::span<LyapunovRecord> records, double dt, std::uint64_t steps,
                   std::span<double> first_growth, std::span<double> alignment = {}) {
    if (alignment.empty()) return after_steps(tangents, records, dt, steps, first_growth, OrthonormalizationHook());
    const AlignmentIndices indices(k_);
    if (alignment.size() != records.size() * indices.factor_size())
      throw InvalidArgument("SALI/GALI: " + std::to_string(alignment.size()) + " numbers of factors for " +
                            std::to_string(records.size()) + " states of " + std::to_string(k_) +
                            " vectors (expected " + std::to_string(records.size() * indices.factor_size()) + ")");
    after_steps(tangents, records, dt, steps, first_growth, [&](std::size_t b, std::span<const double> r) {
      indices.update(alignment.subspan(b * indices.factor_size(), indices.factor_size()), r);
    });
  }

  // after_steps with a hook in place of the SALI/GALI factors (an empty hook: R is not kept).
  void after_steps(PhaseSpaceBatch& tangents, std::span<LyapunovRecord> records, double dt, std::uint64_t steps,
                   std::span<double> first_growth, const OrthonormalizationHook& hook) {
    check(tangents, records);
    if (steps == 0 || steps > steps_to_renormalization(records) || (steps > 1 && !first_growth.empty()))
      throw InvalidArgument("after_steps: " + std::to_string(steps) +
                            " steps at once, which must be at least 1, pass no orthonormalisation and be 1 with "
                            "first_growth");
    if (!first_growth.empty() && first_growth.size() != records.size())
      throw InvalidArgument("first_growth has " + std::to_string(first_growth.size()) + " entries for " +
                            std::to_string(records.size()) + " states");
    const std::size_t n = tangents.dimension();
    std::array<double, LyapunovRecord::max_exponents> log_norms{};
    std::array<double, LyapunovRecord::max_exponents * LyapunovRecord::max_exponents> r;  // written before read
    const std::span<double> triangle = hook ? std::span<double>(r.data(), k_ * k_) : std::span<double>();
    for (std::size_t b = 0; b < records.size(); ++b) {
      LyapunovRecord& record = records[b];
      if (!first_growth.empty()) {
        const std::size_t first = b * k_ * n;
        double squared = 0.0;
        for (std::size_t i = 0; i < n; ++i)
          squared +=
              tangents.q()[first + i] * tangents.q()[first + i] + tangents.p()[first + i] * tangents.p()[first + i];
        const double log_norm = 0.5 * std::log(squared);
        first_growth[b] = log_norm - record.log_norm_first;
        record.log_norm_first = log_norm;
      }
      record.steps += steps;
      for (std::uint64_t step = 0; step < steps; ++step) record.time_since_renormalization += dt;
      record.steps_since_renormalization += steps;
      if (record.steps_since_renormalization < renormalize_every_) continue;
      orthonormalize_state(tangents, k_, b, log_norms, triangle);
      for (std::size_t j = 0; j < k_; ++j) record.log_stretch[j] += log_norms[j];
      if (hook) hook(b, triangle);
      record.time += record.time_since_renormalization;
      record.time_since_renormalization = 0.0;
      record.steps_since_renormalization = 0;
      record.log_norm_first = 0.0;
    }
  }

 private:
  void check(const PhaseSpaceBatch& tangents, std::span<const LyapunovRecord> records) const {
    if (tangents.count() != records.size() * k_)
      throw InvalidArgument(std::to_string(records.size()) + " states with " + std::to_string(k_) +
                            " tangent vectors each need " + std::to_string(records.size() * k_) + " vectors (found " +
                            std::to_string(tangents.count()) + ")");
    if (k_ > 2 * tangents.dimension())
      throw InvalidArgument("at most 2n = " + std::to_string(2 * tangents.dimension()) +
                            " Lyapunov exponents exist in dimension n = " + std::to_string(tangents.dimension()) +
                            " (asked for " + std::to_string(k_) + ")");
  }

  std::size_t k_, renormalize_every_;
};

}  // namespace nonsep
