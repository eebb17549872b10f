// The orthogonal fast Lyapunov indicator (/analysis/ofli, nonsep/core/analysis/orthogonal_fast_lyapunov_indicator.hpp)
// through the `nonsep` executable, against truth: in one degree of freedom the component of a tangent vector across
// the flow is known in closed form, and on paper2d OFLI and FLI agree with the variational equations integrated in
// 32 digits (bench/indicators/reference_mp.py). The plugin refusal is in tests/host/test_host_job_reader.cpp's bad
// jobs; threads, resume and MPI in the ensemble tests beside FLI's.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "host_run_support.hpp"

namespace test_host_orthogonal_fli {

using namespace nonsep::host_testing;

TEST_CASE(
    "OFLI in one degree of freedom: ln(|f(x0)| / min |f(x_s)|) over the steps, exactly, while FLI grows like ln t") {
  // In one degree of freedom the area w x f(x) is conserved along the orbit (both are transported by the tangent map,
  // which preserves area), so |w_perp(t)| |f(x_t)| = |w_perp(0)| |f(x_0)|: OFLI(t) = max over the steps of
  // ln(|f(x_0)| / |f(x_s)|), bounded, while the shear along the orbit makes |w| and FLI grow. paper1d:
  // H = T'(p)^2 V''(q) = (1 + p^2/2)^2 (1 + q^2), f = (dH/dp, -dH/dq).
  const json job = {
      {"model", {{"plugin", "paper1d"}}},
      {"integrator", {{"scheme", "gauss"}, {"stages", 3}}},
      {"initial",
       json::array({{{"q", {0.3}}, {"p", {0.5}}}, {{"q", {1.0}}, {"p", {0.2}}}, {{"q", {1.5}}, {"p", {0.3}}}})},
      {"time", {{"dt", 0.01}, {"steps", 10000}}},
      {"output", {{"every", 1}}},
      {"analysis", {{"fli", true}, {"ofli", true}}}};
  TemporaryFolder folder;
  const auto result = run_named(folder, "run", job);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  std::map<int, double> f0, largest;
  for (const auto& row : table(folder / "run/trajectory.csv")) {
    const double q = cell(row, "q0"), p = cell(row, "p0"), g = 1.0 + 0.5 * p * p;
    const double f = std::hypot(2.0 * q * g * g, 2.0 * p * g * (1.0 + q * q));
    const int trajectory = int(cell(row, "trajectory"));
    if (cell(row, "step") == 0.0) f0[trajectory] = f;
    largest[trajectory] = std::max(largest[trajectory], std::log(f0.at(trajectory) / f));
  }
  const auto rows = table(folder / "run/trajectories.csv");
  REQUIRE(rows.size() == 3);
  for (const auto& row : rows) {
    const int trajectory = int(cell(row, "trajectory"));
    MESSAGE("trajectory " << trajectory << ": OFLI(100) " << row.at("ofli") << ", exact " << largest.at(trajectory)
                          << "; FLI(100) " << row.at("fli"));
    CHECK(largest.at(trajectory) > 0.05);  // the start is not the slowest point of the orbit
    CHECK(std::abs(cell(row, "ofli") - largest.at(trajectory)) < 1e-10);
    CHECK(cell(row, "fli") > std::log(100.0) - 2.0);
  }
}

TEST_CASE("FLI and OFLI(20) on paper2d's chaotic orbit against the variational equations in 32 digits: order 6") {
  // paper2d at coupling 0 on q = (0.5, 0), p = (0, 2.5) (deterministic to t = 20, as MEGNO's accuracy test), gauss 3
  // stages at dt = 0.01 and 0.005 against the suprema on the same steps of the hand-derived variational equations
  // integrated by Gauss-Legendre of order 16 in 32 digits (`python3 bench/indicators/reference_mp.py 0.01 8 32 0`,
  // and 0.005: the suprema are over each grid's steps, so each step has its own reference).
  const double fli_reference[] = {5.97067766380051, 5.97130068622214};
  const double ofli_reference[] = {5.85567357961529, 5.85577548594058};
  double fli_error[2], ofli_error[2];
  TemporaryFolder folder;
  for (int i = 0; i < 2; ++i) {
    const int steps = 2000 << i;
    const json job = {{"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.0}}}}},
                      {"integrator", {{"scheme", "gauss"}, {"stages", 3}}},
                      {"initial", {{"q", {0.5, 0.0}}, {"p", {0.0, 2.5}}}},
                      {"time", {{"dt", 20.0 / steps}, {"steps", steps}}},
                      {"output", {{"every", 0}}},
                      {"analysis", {{"fli", true}, {"ofli", true}}}};
    const std::string name = "run" + std::to_string(steps);
    const auto result = run_named(folder, name, job);
    INFO("stderr: " << result.err);
    REQUIRE(result.status == 0);
    const auto rows = table(folder / name / "trajectories.csv");
    REQUIRE(rows.size() == 1);
    fli_error[i] = std::abs(cell(rows[0], "fli") - fli_reference[i]);
    ofli_error[i] = std::abs(cell(rows[0], "ofli") - ofli_reference[i]);
    MESSAGE("dt = " << 20.0 / steps << ": FLI(20) " << rows[0].at("fli") << ", error " << fli_error[i] << "; OFLI(20) "
                    << rows[0].at("ofli") << ", error " << ofli_error[i]);
  }
  CHECK(fli_error[0] < 2e-6);  // about 1e-6 at dt = 0.01, as MEGNO's 1.3e-6
  CHECK(ofli_error[0] < 2e-6);
  CHECK(std::log2(fli_error[0] / fli_error[1]) > 5.5);
  CHECK(std::log2(ofli_error[0] / ofli_error[1]) > 5.5);
}

TEST_CASE("OFLI needs grad H: refused at /analysis/ofli for a plugin without third derivatives, with the reason") {
  TemporaryFolder folder;
  use_test_plugins();
  json job = blowup_job(state(1.0, 0.5));  // Hessians, no d3T and d3V
  job["analysis"] = {{"fli", true}, {"ofli", true}};
  const auto file = write_job(folder / "job.json", job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "run").string(), file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("/analysis/ofli") != std::string::npos);
  CHECK(result.err.find("no third derivatives") != std::string::npos);
  CHECK(result.err.find("/analysis/fli") == std::string::npos);  // FLI needs the tangent map only
}

}  // namespace test_host_orthogonal_fli
