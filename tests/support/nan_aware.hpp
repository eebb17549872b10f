// The largest of two errors, NaN when either is NaN. std::max and std::fmax both drop a NaN (std::max(0.0, NaN) is
// 0), so a "largest error below tol" check built on them passes when a computation produced NaN.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace nonsep::testing {

inline double max_or_nan(double a, double b) {
  return std::isnan(a) || std::isnan(b) ? std::numeric_limits<double>::quiet_NaN() : std::max(a, b);
}

}  // namespace nonsep::testing
