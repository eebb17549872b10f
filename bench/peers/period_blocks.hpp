#pragma once
// The energy envelope of a long run, shared by the long-time benchmarks (long_time_energy.cpp,
// drift_at_equal_accuracy.cpp): the largest relative energy error per block of periods, blocks log-spaced at 10 per
// decade from the first period, and the slope of log(envelope) against log(period) over the last two decades
// (about 0: bounded; 1: linear drift).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace nonsep::bench {

struct PeriodBlock {
  std::size_t first, last;  // periods first .. last - 1 (period k runs from time k T to (k + 1) T)
  double max_error = 0.0;
};

inline std::vector<PeriodBlock> period_blocks(std::size_t periods) {
  std::vector<PeriodBlock> out;
  std::size_t first = 0;
  for (int k = 1; first < periods; ++k) {
    const auto last = std::min(periods, static_cast<std::size_t>(std::llround(std::pow(10.0, k / 10.0))));
    if (last > first) out.push_back({first, last});
    first = std::max(first, last);
  }
  return out;
}

// NaN with fewer than three blocks there.
inline double slope_of_last_two_decades(const std::vector<PeriodBlock>& envelope, std::size_t periods) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
  for (const PeriodBlock& b : envelope)
    if (b.first * 100 >= periods && b.max_error > 0.0) {
      const double x = std::log10(0.5 * static_cast<double>(b.first + b.last)), y = std::log10(b.max_error);
      sx += x, sy += y, sxx += x * x, sxy += x * y, m += 1;
    }
  return m >= 3 ? (m * sxy - sx * sy) / (m * sxx - sx * sx) : std::nan("");
}

}  // namespace nonsep::bench
