#pragma once
// The per-trajectory record of LyapunovExponents (lyapunov_exponents.hpp): the sums of ln R_jj, the time they cover,
// and the first vector's ln |v_1| since the last orthonormalisation. Trivially copyable, no pointers: a checkpoint
// stores it as numbers.
#include <array>
#include <cstddef>
#include <cstdint>

namespace nonsep {

struct LyapunovRecord {
  static constexpr std::size_t max_exponents = 32;  // 2n for n = 16, the largest dimension the shipped models have

  std::uint64_t steps = 0;  // steps since start()
  std::uint64_t steps_since_renormalization = 0;
  double time = 0.0;  // time at the last orthonormalisation (the exponents' denominator)
  double time_since_renormalization = 0.0;
  double log_norm_first = 0.0;                      // ln |v_1| now; 0 right after an orthonormalisation
  std::array<double, max_exponents> log_stretch{};  // sum of ln R_jj, vector j at index j

  // lambda_j at the last orthonormalisation; 0 before the first.
  double exponent(std::size_t j) const { return time == 0.0 ? 0.0 : log_stretch[j] / time; }
  friend bool operator==(const LyapunovRecord&, const LyapunovRecord&) = default;
};

}  // namespace nonsep
