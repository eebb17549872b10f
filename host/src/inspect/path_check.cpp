// PathDifference and PathCheck (plugin_report.hpp): the comparison rule of the kernel and energy parts of
// `nonsep inspect --check`, written once.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "nonsep/host/inspect/plugin_report.hpp"

namespace nonsep::host {

void PathDifference::add(double expected, double found) {
  if (std::memcmp(&expected, &found, sizeof expected) == 0 || (std::isnan(expected) && std::isnan(found))) return;
  identical = false;
  if (!std::isfinite(expected) || !std::isfinite(found)) {
    comparable = false;
    return;
  }
  largest = std::max(largest, std::abs(expected - found) / std::max(1.0, std::abs(expected)));
}

std::string PathCheck::judge(const PathDifference& difference, double tolerance, const std::string& reference,
                             const std::string& relative_to) {
  largest_difference = std::max(largest_difference, difference.largest);
  if (!difference.comparable) {
    passed = false;
    return "FAILED: non-finite where " + reference + " is finite (or the reverse)";
  }
  char text[64];
  std::snprintf(text, sizeof text, "%.3g", difference.largest);
  std::string verdict = "largest difference from " + reference + " " + text + " (" + relative_to + ")";
  if (difference.largest > tolerance) {
    verdict += ": FAILED, above the tolerance";
    passed = false;
  }
  return verdict;
}

}  // namespace nonsep::host
