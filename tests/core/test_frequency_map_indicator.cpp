// Frequency map analysis behind the indicator seam (frequency_map_indicator.hpp): what it asks of the caller, its
// columns, its analysis of signals whose frequencies are exact (the whole run, both halves and the diffusion index
// against FrequencyAnalysis run directly), a signal it cannot analyse, and the same indicator at another sampling.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <span>
#include <vector>

#include "nonsep/core/analysis/frequency_map_indicator.hpp"

namespace test_frequency_map_indicator {

using namespace nonsep;
using Complex = std::complex<double>;

namespace {

// z_k = a exp(i nu t_k) with a frequency that drifts by `drift` over the run: nu(t) = nu0 (1 + drift t / T).
std::vector<Complex> signal(double nu0, Complex a, double drift, double tau, std::size_t n) {
  std::vector<Complex> z(n);
  const double total = tau * static_cast<double>(n - 1);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = tau * static_cast<double>(k);
    z[k] = a * std::polar(1.0, nu0 * (t + 0.5 * drift * t * t / total));
  }
  return z;
}

}  // namespace

TEST_CASE("frequency map indicator: it asks for samples, not tangent vectors, and names its columns and files") {
  const FrequencyMapIndicator map(3, {1, 0}, 2);
  const IndicatorNeeds needs = map.needs();
  CHECK(needs_samples(map));
  CHECK(needs.tangent_vectors == 0);
  CHECK(needs.state_size == 0);
  CHECK_FALSE(needs.first_growth);
  CHECK_FALSE(needs.across_flow);
  CHECK(needs.samples.every == 3);
  CHECK(needs.samples.degrees == std::vector<std::size_t>{1, 0});
  CHECK(needs.samples.minimum == 32);
  CHECK(needs.samples.file == "frequency_signals.npy");
  CHECK(needs.samples.spectra_file == "frequency_spectra.csv");
  CHECK(FrequencyMapIndicator(1, {0}, 0).needs().samples.spectra_file.empty());
  CHECK(map.columns() == std::vector<std::string>{"frequency1", "frequency1_first", "frequency1_second", "frequency0",
                                                  "frequency0_first", "frequency0_second", "diffusion"});
  CHECK(map.name() == "frequencies");
  CHECK(map.settings() == std::vector<std::pair<std::string, std::size_t>>{{"every", 3}, {"spectra", 2}});

  // Sampling every 15 steps instead (scheme auto's step a fifth of the job's): the same signals and spectra.
  const auto resampled = map.sampling_every(15);
  REQUIRE(resampled);
  CHECK(resampled->needs().samples.every == 15);
  CHECK(resampled->needs().samples.degrees == needs.samples.degrees);
  CHECK(resampled->settings() == std::vector<std::pair<std::string, std::size_t>>{{"every", 15}, {"spectra", 2}});

  // The indicators of the tangent map need no samples.
  CHECK_FALSE(needs_samples(LyapunovIndicator(2)));
}

TEST_CASE("frequency map indicator: the whole run, both halves and the diffusion index of exact signals") {
  const double tau = 0.05;
  const std::size_t n = 4096;
  // Signal 0 on a torus (one frequency), signal 1 drifting by 1e-3 over the run.
  const auto torus = signal(-1.3, {0.7, 0.2}, 0.0, tau, n);
  const auto drifting = signal(2.1, {1.1, 0.0}, 1e-3, tau, n);
  const std::vector<std::span<const Complex>> signals{torus, drifting};
  const FrequencyMapIndicator map(1, {0, 1}, 1);
  const SampleAnalysis result = map.from_samples(signals, tau);
  REQUIRE(result.values.size() == map.columns().size());

  // The same numbers as FrequencyAnalysis gives directly, bit for bit.
  FrequencyAnalysis direct;
  for (std::size_t j = 0; j < 2; ++j) {
    const std::span<const Complex> z = signals[j];
    CHECK(result.values[3 * j] == direct.fundamental_frequency(z, tau));
    CHECK(result.values[3 * j + 1] == direct.fundamental_frequency(z.first(n / 2), tau));
    CHECK(result.values[3 * j + 2] == direct.fundamental_frequency(z.subspan(n / 2, n / 2), tau));
  }
  // Against the exact frequencies: the torus's to 1e-10 in every window; the drifting one's halves see their mean
  // frequencies nu0 (1 + drift / 4) and nu0 (1 + 3 drift / 4).
  for (std::size_t column : {0, 1, 2}) CHECK(std::abs(result.values[column] + 1.3) < 1.3e-10);
  CHECK(std::abs(result.values[4] - 2.1 * (1 + 0.25e-3)) < 2.1e-6);
  CHECK(std::abs(result.values[5] - 2.1 * (1 + 0.75e-3)) < 2.1e-6);
  const double first[] = {result.values[1], result.values[4]}, second[] = {result.values[2], result.values[5]};
  CHECK(result.values[6] == diffusion_index(first, second));
  CHECK(result.values[6] > -4.0);  // log10(0.5e-3 * 2.1 / |(-1.3, 2.1)|) = -3.37
  CHECK(result.values[6] < -2.5);

  // The spectra: the strongest term of each signal over the whole run; none without spectra.
  REQUIRE(result.spectra.size() == 2);
  REQUIRE(result.spectra[0].size() == 1);
  CHECK(result.spectra[0][0].frequency == doctest::Approx(-1.3).epsilon(1e-10));
  CHECK(std::abs(result.spectra[0][0].amplitude - Complex(0.7, 0.2)) < 1e-8);
  const SampleAnalysis without = FrequencyMapIndicator(1, {0, 1}, 0).from_samples(signals, tau);
  CHECK(without.spectra.empty());
  CHECK(without.values == result.values);

  // The columns follow the order of the signals: the same two signals the other way round.
  const std::vector<std::span<const Complex>> swapped{drifting, torus};
  const SampleAnalysis reversed = FrequencyMapIndicator(1, {1, 0}, 0).from_samples(swapped, tau);
  REQUIRE(reversed.values.size() == 7);
  for (std::size_t column = 0; column < 3; ++column) {
    CHECK(reversed.values[column] == result.values[3 + column]);
    CHECK(reversed.values[3 + column] == result.values[column]);
  }
}

TEST_CASE("frequency map indicator: an odd number of samples leaves the last one out of the halves") {
  const double tau = 0.07;
  const std::size_t n = 1001;
  const auto z = signal(0.8, {1.0, 0.0}, 0.0, tau, n);
  const std::vector<std::span<const Complex>> signals{z};
  const SampleAnalysis result = FrequencyMapIndicator(1, {0}, 0).from_samples(signals, tau);
  REQUIRE(result.values.size() == 4);
  FrequencyAnalysis direct;
  const std::span<const Complex> all = z;
  CHECK(result.values[0] == direct.fundamental_frequency(all, tau));
  CHECK(result.values[1] == direct.fundamental_frequency(all.first(500), tau));
  CHECK(result.values[2] == direct.fundamental_frequency(all.subspan(500, 500), tau));
  for (std::size_t column : {0, 1, 2}) CHECK(std::abs(result.values[column] - 0.8) < 1e-10);
}

TEST_CASE("frequency map indicator: a signal with a sample that is not finite gives no values") {
  const double tau = 0.1;
  auto z = signal(0.9, {1.0, 0.0}, 0.0, tau, 64);
  z[40] = {std::numeric_limits<double>::quiet_NaN(), 0.0};
  const std::vector<std::span<const Complex>> signals{z};
  const SampleAnalysis result = FrequencyMapIndicator(1, {0}, 2).from_samples(signals, tau);
  CHECK(result.values.empty());
  CHECK(result.spectra.empty());
}

}  // namespace test_frequency_map_indicator
