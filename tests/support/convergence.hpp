#pragma once
// Least-squares slope of log(error) against log(dt): the measured order of convergence.
#include <cmath>
#include <cstddef>
#include <vector>

namespace nonsep::testing {

inline double fitted_exponent(const std::vector<double>& dt, const std::vector<double>& error) {
  const std::size_t n = dt.size();
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = std::log(dt[i]), y = std::log(std::abs(error[i]));
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace nonsep::testing
