// Frequency map analysis (/analysis/frequencies) against exact frequencies: two uncoupled copies of the paper's 1D
// test written as a formula model, T = p0 + p0^3/6 + p1 + p1^3/6, V = q0^2/2 + q0^4/12 + q1^2/2 + q1^4/12, so that
// H = (1 + p0^2/2)^2 (1 + q0^2) + (1 + p1^2/2)^2 (1 + q1^2) and each degree of freedom is a paper1d orbit whose period
// is known by quadrature (reference/paper1d_exact.hpp). The run's frequencies, its spectra and its signals file are
// checked against them.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "formula_test_support.hpp"
#include "nonsep/reference/paper1d_exact.hpp"

namespace test_formula_frequencies {

using nlohmann::json;
using namespace nonsep::host_testing;
using namespace nonsep::formula_testing;

namespace {

// trajectories.csv's cell `name` of the row of `trajectory`.
double column(const fs::path& file, const std::string& name, std::size_t trajectory) {
  const auto rows = read_csv(file);
  REQUIRE(rows.size() > trajectory + 1);
  for (std::size_t c = 0; c < rows[0].size(); ++c)
    if (rows[0][c] == name) return std::stod(rows[trajectory + 1].at(c));
  FAIL("no column " << name);
  return 0.0;
}

}  // namespace

TEST_CASE("frequency map: two uncoupled paper1d oscillators, each frequency within 1e-10 of 2 pi over its period") {
  // Amplitudes 2 and 1 (periods 1.5455 and 2.3182: the larger amplitude turns faster), 2^14 samples over 1000
  // periods of the slower, Gauss-Legendre with 4 stages (order 8) at dt = 0.0044, whose frequency error (~ dt^8) is
  // below the analysis's. z = q + i p turns clockwise: the frequencies are -2 pi / period. Measured: 2.4e-15 and
  // 8.3e-15 relative (the analysis's T^-4 leakage of the harmonics is below round-off over 1000 periods: the Hann
  // window's error, 1.5e-10 at 1600 periods beside a term 0.3 as strong and 5% away, falls with the distance to
  // the nearest term, here twice the frequency); diffusion index -14.9.
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const double q0 = 2.0, q1 = 1.0;
  const double period0 = 4.0 * nonsep::reference::paper1d_quarter(q0).period;
  const double period1 = 4.0 * nonsep::reference::paper1d_quarter(q1).period;
  const std::uint64_t every = 32, samples = 16384;
  const double t_end = 1000.0 * std::max(period0, period1);
  const json job = {
      {"model",
       {{"formula",
         {{"name", "two_paper1d"}, {"T", "p0 + p0^3/6 + p1 + p1^3/6"}, {"V", "q0^2/2 + q0^4/12 + q1^2/2 + q1^4/12"}}}}},
      {"integrator", {{"scheme", "gauss"}, {"stages", 4}}},
      {"initial", {{"q", {q0, q1}}, {"p", {0.0, 0.0}}}},
      {"time", {{"t_end", t_end}, {"dt", t_end / static_cast<double>(every * samples)}}},
      {"output", {{"every", 0}}},
      {"analysis", {{"frequencies", {{"every", every}, {"spectra", 3}}}}}};
  const auto file = write_job(folder / "job.json", job);
  const auto result = run_nonsep({"run", "--quiet", "-o", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const fs::path table = folder / "out/trajectories.csv";
  const double exact0 = -2.0 * std::numbers::pi / period0, exact1 = -2.0 * std::numbers::pi / period1;
  const double error0 = std::abs(column(table, "frequency0", 0) / exact0 - 1.0);
  const double error1 = std::abs(column(table, "frequency1", 0) / exact1 - 1.0);
  MESSAGE("periods " << period0 << ", " << period1 << ", dt " << t_end / static_cast<double>(every * samples)
                     << "; relative errors " << error0 << ", " << error1 << "; diffusion "
                     << column(table, "diffusion", 0));
  CHECK(error0 <= 1e-10);
  CHECK(error1 <= 1e-10);
  CHECK(column(table, "diffusion", 0) < -9.0);
  for (const char* half : {"frequency0_first", "frequency0_second"})
    CHECK(std::abs(column(table, half, 0) / exact0 - 1.0) <= 1e-9);

  // The error against the length T of the run: like T^-4 (the Hann window's leakage from the other terms) until
  // round-off. 4096 samples over 10 to 160 periods of the slower oscillator, each 8 steps apart (dt = T / 32768).
  // Measured: 4.1e-7, 2.6e-8, 1.6e-9, 9.7e-11, 5.4e-12 relative for nu_0; fitted exponent -4.05.
  std::vector<double> log_t, log_error;
  for (double periods = 10.0; periods <= 160.0; periods *= 2.0) {
    json shorter = job;
    const double t = periods * std::max(period0, period1);
    shorter["time"] = {{"t_end", t}, {"dt", t / 32768.0}};
    shorter["analysis"]["frequencies"] = {{"every", 8}};
    const auto name = "periods-" + std::to_string(static_cast<int>(periods));
    const auto short_file = write_job(folder / (name + ".json"), shorter);
    REQUIRE(run_nonsep({"run", "--quiet", "-o", (folder / name).string(), short_file.string()}, folder.path()).status ==
            0);
    const double error = std::abs(column(folder / name / "trajectories.csv", "frequency0", 0) / exact0 - 1.0);
    MESSAGE(periods << " periods: relative error " << error);
    log_t.push_back(std::log(t));
    log_error.push_back(std::log(error));
  }
  const double n = static_cast<double>(log_t.size());
  double st = 0, se = 0, stt = 0, ste = 0;
  for (std::size_t i = 0; i < log_t.size(); ++i) {
    st += log_t[i];
    se += log_error[i];
    stt += log_t[i] * log_t[i];
    ste += log_t[i] * log_error[i];
  }
  const double exponent = (n * ste - st * se) / (n * stt - st * st);
  MESSAGE("fitted exponent " << exponent);
  CHECK(exponent == doctest::Approx(-4.0).epsilon(0.08));

  // The spectra: per signal three terms, the first the column's frequency; the others are the orbit's harmonics
  // (paper1d's q + i p is not a circle): odd multiples of the fundamental, here -nu and 3 nu.
  const auto spectra = read_csv(folder / "out/frequency_spectra.csv");
  REQUIRE(spectra.size() == 1 + 2 * 3);
  CHECK(spectra[0] ==
        std::vector<std::string>{"trajectory", "signal", "term", "frequency", "amplitude_re", "amplitude_im"});
  CHECK(std::stod(spectra[1][3]) == column(table, "frequency0", 0));
  CHECK(std::stod(spectra[4][3]) == column(table, "frequency1", 0));
  for (std::size_t row = 1; row < spectra.size(); ++row) {
    const double nu = std::stod(spectra[row][1]) == 0.0 ? exact0 : exact1;
    const double ratio = std::stod(spectra[row][3]) / nu;
    CAPTURE(row);
    CHECK(std::abs(ratio - std::round(ratio)) < 1e-6);
    CHECK(std::abs(std::lround(ratio)) % 2 == 1);
  }

  // The signals: a (1, 2, 2^14) complex array whose first sample is the state after `every` steps (|z| near the
  // amplitude: p is small there) and whose samples lie on the energy shell of each oscillator.
  std::ifstream npy(folder / "out/frequency_signals.npy", std::ios::binary);
  std::string header(128, '\0');
  npy.read(header.data(), 128);
  const std::size_t length = static_cast<unsigned char>(header[8]) + 256u * static_cast<unsigned char>(header[9]);
  CHECK(header.substr(0, 6) == "\x93NUMPY");
  CHECK(header.find("'shape': (1, 2, 16384)") != std::string::npos);
  CHECK((10 + length) % 64 == 0);
  npy.seekg(static_cast<std::streamoff>(10 + length));
  std::vector<std::complex<double>> z(2 * samples);
  npy.read(reinterpret_cast<char*>(z.data()), static_cast<std::streamsize>(z.size() * sizeof z[0]));
  REQUIRE(npy.gcount() == static_cast<std::streamsize>(z.size() * sizeof z[0]));
  for (std::size_t j = 0; j < 2; ++j) {
    const double energy = 1.0 + (j == 0 ? q0 * q0 : q1 * q1);
    for (std::size_t k = 0; k < samples; k += 997) {
      const std::complex<double> s = z[j * samples + k];
      const double h = std::pow(1.0 + s.imag() * s.imag() / 2.0, 2) * (1.0 + s.real() * s.real());
      CHECK(std::abs(h / energy - 1.0) < 1e-9);
    }
  }
}

}  // namespace test_formula_frequencies
