// The cost of frequency analysis (NAFF, core/include/nonsep/core/analysis/frequency_analysis.hpp) on one core:
// the fundamental frequency of 2^14 samples (a whole run) and of 2^13 (one half of it), and the 3 strongest terms
// of 2^14, each on a two-frequency torus z_k = exp(i t_k) + 0.3 exp(-i sqrt(2) t_k) over 1000 periods of the first
// term. One FrequencyAnalysis object is reused, as a run would (the FFT's tables are built once per length).
// Each figure is the median over the repetitions of the time of one analysis, with the fastest and slowest, in
// milliseconds and in nanoseconds per sample; the last line is what frequency map analysis of 1024 orbits with 2
// degrees of freedom costs (3 windows per degree of freedom: both halves and the whole run).
// Every result is checked against the exact frequencies, so a faster but wrong path cannot pass.
//
// Usage: nonsep_bench_frequency_analysis [--smoke] [--repetitions N]
//   --smoke         5 repetitions (the ctest bench.frequency_analysis.smoke)
//   --repetitions   default 201
// Exit status 1 when a frequency is off by more than 1e-12 relative, 2 for bad arguments.
#include "nonsep/core/analysis/frequency_analysis.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Spread {
  double median, fastest, slowest;
};

Spread spread(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return {values[values.size() / 2], values.front(), values.back()};
}

const double second_frequency = -std::sqrt(2.0);

std::vector<std::complex<double>> torus(std::size_t n, double tau) {
  std::vector<std::complex<double>> z(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * tau;
    z[k] = std::polar(1.0, t) + 0.3 * std::polar(1.0, second_frequency * t);
  }
  return z;
}

// The median time of one analysis of `z` asking `count` terms; false when a frequency is wrong.
bool measure(nonsep::FrequencyAnalysis& analysis, const std::vector<std::complex<double>>& z, double tau,
             std::size_t count, int repetitions, const char* label, Spread& result) {
  std::vector<double> seconds;
  bool right = true;
  for (int r = 0; r < repetitions; ++r) {
    const auto start = Clock::now();
    const auto terms = analysis.terms(z, tau, count);
    seconds.push_back(std::chrono::duration<double>(Clock::now() - start).count());
    right = right && std::abs(terms[0].frequency - 1.0) < 1e-12 &&
            (count < 2 || std::abs(terms[1].frequency / second_frequency - 1.0) < 1e-12);
  }
  result = spread(seconds);
  const double per_sample = 1e9 / static_cast<double>(z.size());
  std::printf("%-34s %6zu samples  %7.3f ms (%.3f .. %.3f)  %6.1f ns/sample\n", label, z.size(), 1e3 * result.median,
              1e3 * result.fastest, 1e3 * result.slowest, result.median * per_sample);
  return right;
}

}  // namespace

int main(int argc, char** argv) {
  int repetitions = 201;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke") {
      repetitions = 5;
    } else if (arg == "--repetitions" && i + 1 < argc) {
      repetitions = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "usage: nonsep_bench_frequency_analysis [--smoke] [--repetitions N]\n");
      return 2;
    }
  }
  if (repetitions < 1) {
    std::fprintf(stderr, "--repetitions must be at least 1\n");
    return 2;
  }
  const std::size_t whole = std::size_t{1} << 14, half = whole / 2;
  const double tau = 1000.0 * 2.0 * std::numbers::pi / static_cast<double>(whole - 1);
  const auto z = torus(whole, tau);
  const std::vector<std::complex<double>> first_half(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(half));
  nonsep::FrequencyAnalysis analysis;
  Spread whole_time{}, half_time{}, three_terms{};
  bool right = measure(analysis, z, tau, 1, repetitions, "fundamental frequency", whole_time);
  right = measure(analysis, first_half, tau, 1, repetitions, "fundamental frequency, half", half_time) && right;
  right = measure(analysis, z, tau, 3, repetitions, "3 strongest terms", three_terms) && right;
  const double map_seconds = 1024.0 * 2.0 * (whole_time.median + 2.0 * half_time.median);
  std::printf("frequency map of 1024 orbits, 2 degrees of freedom, 3 windows each: %.2f s on one core\n", map_seconds);
  if (!right) {
    std::fprintf(stderr, "a frequency is off by more than 1e-12 relative\n");
    return 1;
  }
  return 0;
}
