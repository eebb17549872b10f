// Frequency analysis (NAFF) against exact truth: synthetic quasi-periodic signals whose frequencies and amplitudes
// are known, the T^-4 law of the Hann window, an orbit of the paper's 1D test whose period is known from its energy
// (reference/paper1d_exact.hpp), the diffusion index of a torus and of a drifting frequency, and each bad input.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <vector>

#include "nonsep/core/analysis/frequency_analysis.hpp"
#include "nonsep/core/base/error.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "support/convergence.hpp"

namespace test_frequency_analysis {

using namespace nonsep;
using Complex = std::complex<double>;

namespace {

constexpr double two_pi = 2.0 * std::numbers::pi;

struct Term {
  double frequency;
  Complex amplitude;
};

// z_k = sum_j a_j exp(i nu_j k tau), k = 0 .. n-1.
std::vector<Complex> quasi_periodic(const std::vector<Term>& terms, double tau, std::size_t n) {
  std::vector<Complex> z(n);
  for (std::size_t k = 0; k < n; ++k)
    for (const Term& term : terms)
      z[k] += term.amplitude * std::polar(1.0, term.frequency * static_cast<double>(k) * tau);
  return z;
}

double relative_error(double found, double exact) { return std::abs(found - exact) / std::abs(exact); }

}  // namespace

TEST_CASE("frequency analysis finds the frequencies and amplitudes of a quasi-periodic signal") {
  // Three incommensurate terms, one turning the other way, amplitudes 1 : 0.3 : 0.05, over 1000 periods of the
  // first in 2^14 samples. Measured: frequencies within 2.5e-14, 1.6e-16 and 0 relative (the strongest one biased
  // by the others' leakage, ~T^-4), amplitudes within 8e-11, 5e-12 and 4e-14 relative.
  const std::vector<Term> exact{{1.0, {1.0, 0.2}}, {-std::sqrt(2.0), {0.3, -0.1}}, {std::sqrt(5.0), {-0.05, 0.02}}};
  const std::size_t n = std::size_t{1} << 14;
  const double tau = 1000.0 * two_pi / static_cast<double>(n - 1);
  FrequencyAnalysis analysis;
  const auto found = analysis.terms(quasi_periodic(exact, tau, n), tau, 3);
  REQUIRE(found.size() == 3);
  for (std::size_t j = 0; j < 3; ++j) {
    CAPTURE(j);
    CHECK(relative_error(found[j].frequency, exact[j].frequency) < 1e-12);
    CHECK(std::abs(found[j].amplitude - exact[j].amplitude) / std::abs(exact[j].amplitude) < 1e-9);
  }
  CHECK(analysis.fundamental_frequency(quasi_periodic(exact, tau, n), tau) == found[0].frequency);

  // A harmonic oscillator's q + i p turns clockwise: a negative frequency. Any length works (the FFT is padded).
  const std::size_t odd = 1001;
  std::vector<Complex> oscillator(odd);
  for (std::size_t k = 0; k < odd; ++k)
    oscillator[k] = {std::cos(0.3 * static_cast<double>(k)), -std::sin(0.3 * static_cast<double>(k))};
  const auto rotation = analysis.terms(oscillator, 0.1, 1);
  CHECK(relative_error(rotation[0].frequency, -3.0) < 1e-13);
  CHECK(std::abs(rotation[0].amplitude - 1.0) < 1e-12);
}

TEST_CASE("frequency analysis: the error of a frequency falls like T^-4 with the Hann window") {
  // nu = 1 with a term 0.3 exp(i (1.05 t + 1)) beside it, sampled 10.3 times per period over T = 100 .. 1600
  // periods. Measured: errors 1.05e-5, 6.3e-7, 3.9e-8, 2.5e-9, 1.5e-10, fitted exponent -4.01. The law goes on to
  // 2.4e-15 at T = 25600 periods and reaches the floor, one ulp of nu (2.2e-16), at 51200. Without the window
  // (chi = 1) the exponent is -2.0 and the error at 1600 periods 3.8e-7.
  const double tau = two_pi / 10.3;
  std::vector<double> lengths, errors;
  FrequencyAnalysis analysis;
  for (double periods = 100.0; periods <= 1600.0; periods *= 2.0) {
    const auto n = static_cast<std::size_t>(std::ceil(periods * two_pi / tau)) + 1;
    const auto z = quasi_periodic({{1.0, 1.0}, {1.05, std::polar(0.3, 1.0)}}, tau, n);
    lengths.push_back(static_cast<double>(n - 1) * tau);
    errors.push_back(std::abs(analysis.fundamental_frequency(z, tau) - 1.0));
  }
  const double exponent = nonsep::testing::fitted_exponent(lengths, errors);
  CAPTURE(errors);
  CHECK(exponent == doctest::Approx(-4.0).epsilon(0.05));
  CHECK(errors.back() < 1e-9);
}

TEST_CASE("frequency analysis: the fundamental frequency of paper1d's orbit is 2 pi over its exact period") {
  // H = (1 + p^2/2)^2 (1 + q^2) from (q, p) = (2, 0): a period of 4 quarter periods by quadrature. The orbit,
  // sampled by Runge-Kutta-Fehlberg 7(8) at tolerance 1e-14 (reference/hamiltonian_flow.hpp), 2^14 samples over
  // 1000 periods. z = q + i p turns clockwise: the frequency is -2 pi / period. Measured: 9.3e-12 relative.
  const double q0 = 2.0;
  const double period = 4.0 * reference::paper1d_quarter(q0).period;
  const std::size_t n = std::size_t{1} << 14;
  const double tau = 1000.0 * period / static_cast<double>(n - 1);
  auto rhs = [](const std::vector<double>& x, std::vector<double>& dxdt) {
    const double q = x[0], p = x[1], u = 1.0 + 0.5 * p * p;
    dxdt[0] = 2.0 * u * p * (1.0 + q * q);  // dH/dp
    dxdt[1] = -2.0 * u * u * q;             // -dH/dq
  };
  const auto states = reference::hamiltonian_flow_samples(rhs, {q0, 0.0}, tau, n);
  std::vector<Complex> z(n);
  for (std::size_t k = 0; k < n; ++k) z[k] = {states[k][0], states[k][1]};
  FrequencyAnalysis analysis;
  const double exact = -two_pi / period;
  const double found = analysis.fundamental_frequency(z, tau);
  CAPTURE(found);
  CAPTURE(exact);
  CHECK(relative_error(found, exact) < 1e-10);
}

TEST_CASE("frequency analysis: the diffusion index tells a torus from a drifting frequency") {
  // The two halves of a run of 2^15 samples, 2000 periods of nu = 1. On a two-frequency torus the index is at the
  // method's error (measured -14.4); with the frequency drifting, z = exp(i (t + eps t^2 / 2)), each half sees its
  // mean frequency, 1 + eps T/4 and 1 + 3 eps T/4: the index is log10((eps T/2) / (1 + 3 eps T/4)), -4.00 for
  // eps T = 2e-4 (measured: within 1e-10 of it).
  const std::size_t n = std::size_t{1} << 15, half = n / 2;
  const double tau = 2000.0 * two_pi / static_cast<double>(n - 1);
  const double length = static_cast<double>(n - 1) * tau;
  FrequencyAnalysis analysis;
  auto index = [&](const std::vector<Complex>& z) {
    const double first = analysis.fundamental_frequency({z.data(), half}, tau);
    const double second = analysis.fundamental_frequency({z.data() + half, half}, tau);
    return diffusion_index(std::vector{first}, std::vector{second});
  };
  const double torus = index(quasi_periodic({{1.0, 1.0}, {-std::sqrt(3.0), 0.4}}, tau, n));
  CAPTURE(torus);
  CHECK(torus < -12.0);

  const double eps = 2e-4 / length;
  std::vector<Complex> drifting(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * tau;
    drifting[k] = std::polar(1.0, t + 0.5 * eps * t * t);
  }
  const double half_length = static_cast<double>(half) * tau;  // the second half starts one sample after T/2
  const double first_mean = 1.0 + eps * 0.5 * static_cast<double>(half - 1) * tau;
  const double second_mean = 1.0 + eps * (half_length + 0.5 * static_cast<double>(half - 1) * tau);
  const double expected = std::log10((second_mean - first_mean) / second_mean);
  const double drift = index(drifting);
  CAPTURE(drift - expected);
  CHECK(std::abs(drift - expected) < 1e-10);
  CHECK(expected == doctest::Approx(-4.0).epsilon(1e-3));

  // Several degrees of freedom: Euclidean norms; identical frequencies give the floor, log10 of the epsilon.
  CHECK(diffusion_index(std::vector{3.0, 4.0}, std::vector{3.0, 4.0 + 5e-6}) ==
        doctest::Approx(std::log10(5e-6 / std::hypot(3.0, 4.0 + 5e-6))).epsilon(1e-9));
  CHECK(diffusion_index(std::vector{0.0}, std::vector{0.0}) == std::log10(std::numeric_limits<double>::epsilon()));
}

TEST_CASE("frequency analysis: terms beyond those of the signal are at round-off, and a zero signal has one") {
  // A pure tone asked for 3 terms: the 2 extra ones are what its subtraction leaves (measured 2e-14 of it; 4e-10
  // when the projection ignores that the exponentials are not orthogonal, G = identity).
  FrequencyAnalysis analysis;
  const auto tone = analysis.terms(quasi_periodic({{7.7, {0.3, -0.4}}}, 0.1, 4096), 0.1, 3);
  REQUIRE(tone.size() == 3);
  CHECK(relative_error(tone[0].frequency, 7.7) < 1e-14);
  CHECK(std::abs(tone[1].amplitude) < 1e-12);
  CHECK(std::abs(tone[2].amplitude) < 1e-12);
  // A zero signal: frequency 0, amplitude 0, and the next exponential (at 0 again) is in the span of the first,
  // which ends the search.
  const auto zero = analysis.terms(std::vector<Complex>(64), 0.1, 3);
  REQUIRE(zero.size() == 1);
  CHECK(zero[0].frequency == 0.0);
  CHECK(zero[0].amplitude == Complex{});
}

TEST_CASE("frequency analysis: each bad input gets its own error") {
  FrequencyAnalysis analysis;
  const auto z = quasi_periodic({{1.0, 1.0}}, 0.1, 64);
  CHECK_THROWS_WITH_AS(analysis.terms({z.data(), 15}, 0.1, 1), "frequency analysis: 15 samples, at least 16 needed",
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(analysis.terms({}, 0.1, 1), "frequency analysis: 0 samples, at least 16 needed",
                       InvalidArgument);
  for (double tau : {0.0, -0.1, std::numeric_limits<double>::infinity(), std::nan("")})
    CHECK_THROWS_WITH_AS(analysis.terms(z, tau, 1),
                         doctest::Contains("the sampling interval tau must be finite and positive"), InvalidArgument);
  CHECK_THROWS_WITH_AS(analysis.terms(z, 0.1, 0), "frequency analysis: asked for 0 terms, at least 1 needed",
                       InvalidArgument);
  auto bad = z;
  bad[17] = {1.0, std::numeric_limits<double>::infinity()};
  CHECK_THROWS_WITH_AS(analysis.terms(bad, 0.1, 1), "frequency analysis: sample 17 of 64 is not finite",
                       InvalidArgument);
  bad[17] = {std::nan(""), 0.0};
  CHECK_THROWS_WITH_AS(analysis.fundamental_frequency(bad, 0.1), "frequency analysis: sample 17 of 64 is not finite",
                       InvalidArgument);
  // The object still works after an error.
  CHECK(relative_error(analysis.fundamental_frequency(z, 0.1), 1.0) < 1e-12);

  CHECK_THROWS_WITH_AS(diffusion_index(std::vector{1.0}, std::vector{1.0, 2.0}),
                       doctest::Contains("1 frequencies in the first window and 2 in the second"), InvalidArgument);
  CHECK_THROWS_WITH_AS(diffusion_index({}, {}), doctest::Contains("0 frequencies in the first window"),
                       InvalidArgument);
  CHECK_THROWS_WITH_AS(diffusion_index(std::vector{1.0, 2.0}, std::vector{1.0, std::nan("")}),
                       doctest::Contains("frequency 1 is not finite"), InvalidArgument);
}

}  // namespace test_frequency_analysis
