// SALI and GALI through the `nonsep` executable on paper2d (coupling 0.2, MPE of order 4): the chaotic orbit
// q = (0.5, 0), p = (0, 2.5) and the regular ones q = (0, 0), p = (0.5, 2) and q = (0.25, 0.3), p = (-1.5, 0.2).
// SALI tells them apart; GALI_k follows its laws, exponential decay at the rates sum_{j<=k} (l_1 - l_j) on the
// chaotic orbit and power laws on the 2-tori (constant for k <= 2, t^(-2(k-2)) for k = 3, 4 on a torus whose shear
// is not degenerate). Also: the shared tangent vectors
// leave the Lyapunov exponents and MEGNO bit for bit. (--threads and resume with SALI and GALI:
// test_host_dynamics.cpp's ensemble job.)
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "host_run_support.hpp"

namespace test_host_alignment_indices {

using namespace nonsep::host_testing;

namespace {

// Orbits of paper2d with 4 tangent vectors (the whole spectrum), SALI and GALI_2 .. GALI_4, lyapunov.csv every
// `every` steps; returns lyapunov.csv's columns by name, for each trajectory.
std::vector<std::map<std::string, std::vector<double>>> run_orbits(const TemporaryFolder& folder,
                                                                   const std::string& name, const json& initial,
                                                                   double dt, double t_end, std::uint64_t every) {
  const json job = {
      {"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.2}}}}},
      {"integrator", {{"scheme", "mpe"}, {"order", 4}}},
      {"initial", initial},
      {"time", {{"dt", dt}, {"t_end", t_end}}},
      {"output", {{"every", 0}}},
      {"analysis",
       {{"lyapunov", {{"vectors", 4}, {"renormalize_every", 10}, {"every", every}}}, {"sali", true}, {"gali", 4}}}};
  const auto file = write_job(folder / (name + ".json"), job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = read_csv(folder / name / "lyapunov.csv");
  REQUIRE(rows.size() > 10);
  std::vector<std::map<std::string, std::vector<double>>> columns(initial.size());
  for (std::size_t r = 1; r < rows.size(); ++r)
    for (std::size_t c = 0; c < rows[0].size(); ++c)
      columns[std::stoul(rows[r][0])][rows[0][c]].push_back(std::stod(rows[r][c]));
  return columns;
}

// The least-squares slope of y over x, on the rows where from <= t <= to.
double slope(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& t, double from,
             double to) {
  double n = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t[i] >= from && t[i] <= to) n += 1.0, sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::vector<double> logs(const std::vector<double>& values) {
  std::vector<double> result;
  for (double v : values) result.push_back(std::log(v));
  return result;
}

}  // namespace

TEST_CASE("chaotic orbit: SALI below 1e-8 by t = 50, GALI_k decays at the rate sum_{j<=k} (l_1 - l_j)") {
  TemporaryFolder folder;
  // dt = 5e-4: |dH/H0| ~ 1e-3 at H = 21.4 (the orbit needs a small step; MPE 4 at 2.5e-4 is the reference of the
  // scheme comparisons). lyapunov.csv every t = 0.5.
  auto c = run_orbits(folder, "chaotic", {{"q", {0.5, 0.0}}, {"p", {0.0, 2.5}}}, 5e-4, 50.0, 1000)[0];
  const auto& t = c["t"];
  double first_below = -1.0;
  for (std::size_t i = 0; i < t.size() && first_below < 0.0; ++i)
    if (c["sali"][i] < 1e-8) first_below = t[i];
  MESSAGE("SALI < 1e-8 from t = " << first_below << "; at t = 50: SALI " << c["sali"].back() << ", GALI_4 "
                                  << c["gali4"].back());
  CHECK(first_below > 0.0);
  CHECK(c["sali"].back() < 1e-8);
  // The law, with the run's own spectrum: ln GALI_k(t) against L_k(t) = sum_{j=2..k} (l_1(t) - l_j(t)) t over
  // t in [10, 50] has slope -1 (GALI_4 reaches 1e-120 there: no floor at round-off).
  std::vector<std::vector<double>> sums(4);
  for (std::size_t j = 0; j < 4; ++j)
    for (std::size_t i = 0; i < t.size(); ++i) sums[j].push_back(c["lyapunov" + std::to_string(j)][i] * t[i]);
  std::map<int, double> rate;
  for (int k = 2; k <= 4; ++k) {
    std::vector<double> law(t.size(), 0.0);
    for (std::size_t i = 0; i < t.size(); ++i)
      for (int j = 1; j < k; ++j) law[i] += sums[0][i] - sums[static_cast<std::size_t>(j)][i];
    const auto log_gali = logs(c["gali" + std::to_string(k)]);
    CAPTURE(k);
    CHECK(slope(law, log_gali, t, 10.0, 50.0) == doctest::Approx(-1.0).epsilon(0.05));
    rate[k] = -slope(t, log_gali, t, 10.0, 50.0);
  }
  // The spectrum of a 2-degree-of-freedom flow is (l, 0, 0, -l): the rates are l, 2 l, 4 l.
  const double l1 = (sums[0].back() - sums[0][19]) / (t.back() - t[19]);  // over [10, 50]
  MESSAGE("rates of GALI_2, 3, 4 over t in [10, 50]: " << rate[2] << ", " << rate[3] << ", " << rate[4]
                                                       << "; l_1 there " << l1);
  CHECK(t[19] == 10.0);
  CHECK(rate[3] / rate[2] == doctest::Approx(2.0).epsilon(0.1));
  CHECK(rate[4] / rate[2] == doctest::Approx(4.0).epsilon(0.1));
  CHECK(rate[2] == doctest::Approx(l1).epsilon(0.2));
}

TEST_CASE("regular orbits: SALI stays above 1e-5 to t = 200, GALI_k follows the power laws of their 2-tori") {
  TemporaryFolder folder;
  // dt = 5e-3: |dH/H0| = 6e-5 at t = 200; GALI_2 of the first orbit is the same at dt = 2.5e-3 (medians over
  // [200, 1000] within 2%). lyapunov.csv every t = 2.
  const json initial = json::array({{{"q", {0.0, 0.0}}, {"p", {0.5, 2.0}}}, {{"q", {0.25, 0.3}}, {"p", {-1.5, 0.2}}}});
  auto orbits = run_orbits(folder, "regular", initial, 5e-3, 1000.0, 400);
  for (std::size_t o = 0; o < 2; ++o) {
    auto& c = orbits[o];
    const auto& t = c["t"];
    const auto log_t = logs(t);
    double smallest = 1.0;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] >= 20.0 && t[i] <= 200.0) smallest = std::min(smallest, c["sali"][i]);
    REQUIRE(t[99] == 200.0);
    const double s2 = slope(log_t, logs(c["gali2"]), t, 200.0, 1000.0),
                 s3 = slope(log_t, logs(c["gali3"]), t, 200.0, 1000.0),
                 s4 = slope(log_t, logs(c["gali4"]), t, 200.0, 1000.0);
    MESSAGE("orbit " << o << ": smallest SALI over t in [20, 200] " << smallest << ", at t = 200 " << c["sali"][99]
                     << "; log-log slopes over t in [200, 1000]: GALI_2 " << s2 << ", GALI_3 " << s3 << ", GALI_4 "
                     << s4);
    CAPTURE(o);
    CHECK(smallest > 1e-5);
    // q = (0.25, 0.3), p = (-1.5, 0.2): GALI_2 constant, GALI_3 ~ t^-2, GALI_4 ~ t^-4 (N = 2). q = (0, 0),
    // p = (0.5, 2): a torus whose shear has rank 1 (the deviations grow along one direction only), so the two
    // vectors' growing parts align and GALI_2 ~ t^-1 (then GALI_3 ~ t^-2, GALI_4 ~ t^-4 as well).
    CHECK(s2 == doctest::Approx(o == 0 ? -1.0 : 0.0).scale(1.0).epsilon(0.2));
    CHECK(s3 == doctest::Approx(-2.0).epsilon(0.1));
    CHECK(s4 == doctest::Approx(-4.0).epsilon(0.1));
  }
}

TEST_CASE("SALI and GALI share the tangent vectors: the Lyapunov exponents and MEGNO are the same bit for bit") {
  TemporaryFolder folder;
  json job = {
      {"model", {{"plugin", "paper2d"}}},
      {"integrator", {{"scheme", "mpe"}, {"order", 4}}},
      {"initial", json::array({{{"q", {0.25, 0.3}}, {"p", {-1.5, 0.2}}}, {{"q", {-0.75, 0.3}}, {"p", {-1.5, 0.2}}}})},
      {"time", {{"dt", 0.005}, {"steps", 4000}}},
      {"output", {{"every", 0}}},
      {"analysis", {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 3}, {"every", 500}}}, {"megno", true}}}};
  json with = job;
  with["analysis"]["sali"] = true;
  with["analysis"]["gali"] = 3;
  json alone = job;
  alone["analysis"].erase("megno");
  for (const auto& [name, each] : {std::pair{"plain", job}, std::pair{"with", with}, std::pair{"alone", alone}}) {
    const auto file = write_job(folder / (std::string(name) + ".json"), each);
    REQUIRE(run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path()).status ==
            0);
  }
  const auto plain = read_csv(folder / "plain/trajectories.csv"), shared = read_csv(folder / "with/trajectories.csv"),
             lyapunov_only = read_csv(folder / "alone/trajectories.csv");
  // The columns of the plain run come first in the run with SALI and GALI, the same text.
  REQUIRE(shared[0].size() == plain[0].size() + 3);
  CHECK(shared[0][plain[0].size()] == "sali");
  CHECK(shared[0].back() == "gali3");
  for (std::size_t r = 0; r < plain.size(); ++r)
    for (std::size_t c = 0; c < plain[r].size(); ++c) CHECK(shared[r][c] == plain[r][c]);
  // Without MEGNO (its logarithm is then not computed), the exponents are those of the run with it.
  const auto index = [](const std::vector<std::string>& header, const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  CHECK(index(lyapunov_only[0], "megno") == lyapunov_only[0].size());
  for (std::size_t r = 1; r < plain.size(); ++r)
    CHECK(lyapunov_only[r][index(lyapunov_only[0], "lyapunov0")] == plain[r][index(plain[0], "lyapunov0")]);
  // lyapunov.csv: the series columns, its last row the final values.
  const auto series = read_csv(folder / "with/lyapunov.csv");
  CHECK(series[0] == std::vector<std::string>{"trajectory", "step", "t", "lyapunov0", "megno", "mean_megno", "sali",
                                              "gali2", "gali3"});
  CHECK(series.back()[6] == shared[2][index(shared[0], "sali")]);
  CHECK(series.back()[8] == shared[2][index(shared[0], "gali3")]);
  const json summary = read_json(folder / "with/summary.json");
  CHECK(summary["analysis"]["tangent_map"]["vectors"] == 3);
  CHECK(summary["analysis"]["tangent_map"]["gali"]["vectors"] == 3);
}

}  // namespace test_host_alignment_indices
