// Formula models given by the gradient of T ("dT") instead of T, through the `nonsep` executable with the real
// compiler: Tao's H = (1 + q^2)(1 + p^2)/2 from T' = sqrt((1 + p^2)/2) gives the states of the shipped tao_product
// plugin (its analytic grad T is the same formula); a dT that is no gradient (an asymmetric Jacobian) is refused at
// the initial states; and two coupled Tao oscillators with c = 1/2, whose energy shells are not compact (docs/
// method.md, "Non-compact energy shells"), get the runaway warning instead of the advice to shrink dt.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "host_test_support.hpp"

namespace test_formula_gradients {

using nlohmann::json;
using namespace nonsep::host_testing;
namespace fs = std::filesystem;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

json run_job_with(json model, json initial, json time) {
  return {{"model", std::move(model)},
          {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
          {"initial", std::move(initial)},
          {"time", std::move(time)},
          {"output", {{"every", 0}}}};
}

// The compile takes seconds on an idle machine and minutes on a loaded one: a generous limit, not a timing.
Result run_compiling(const std::vector<std::string>& args, const fs::path& folder) {
  return finish(start_nonsep(args, folder), std::chrono::seconds(900));
}

}  // namespace

TEST_CASE("formula gradients: a T given by its gradient dT gives the states of the tao_product plugin") {
  TemporaryFolder folder;
  ::setenv("NONSEP_CACHE_DIR", (folder / "cache").string().c_str(), 1);
  const json initial = {{{"q", {0.5}}, {"p", {0.25}}}, {{"q", {-1.0}}, {"p", {0.75}}}};
  const json time = {{"dt", 0.01}, {"steps", 300}};
  const json formula = {{"name", "tao_by_gradient"}, {"dT", {"sqrt((1 + p0^2)/2)"}}, {"V", "q0^2/2 + q0^4/12"}};
  const auto formula_file = write_job(folder / "formula.json", run_job_with({{"formula", formula}}, initial, time));
  const auto by_formula =
      run_compiling({"run", "--quiet", "-o", (folder / "formula").string(), formula_file.string()}, folder.path());
  INFO("stderr: " << by_formula.err);
  REQUIRE(by_formula.status == 0);
  const auto plugin_file = write_job(folder / "plugin.json", run_job_with({{"plugin", "tao_product"}}, initial, time));
  REQUIRE(
      run_nonsep({"run", "--quiet", "-o", (folder / "plugin").string(), plugin_file.string()}, folder.path()).status ==
      0);
  const json a = read_run(folder / "formula");
  const json b = read_run(folder / "plugin");
  REQUIRE(a["trajectories"].size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    const json& x = a["trajectories"][i];
    const json& y = b["trajectories"][i];
    const double scale = std::hypot(y["final"]["q"][0].get<double>(), y["final"]["p"][0].get<double>());
    for (const char* part : {"q", "p"})
      CHECK(std::abs(x["final"][part][0].get<double>() - y["final"][part][0].get<double>()) <= 1e-13 * scale);
    // The energy needs grad T and Hess V only: the same H as the plugin's.
    CHECK(x["energy"]["initial"].get<double>() == doctest::Approx(y["energy"]["initial"].get<double>()).epsilon(1e-14));
  }
  CHECK(a["model"]["formula"]["T"] == "grad T = [sqrt((1 + p0^2)/2)]");
  ::unsetenv("NONSEP_CACHE_DIR");
}

TEST_CASE("formula gradients: a dT whose Jacobian is not symmetric is refused at the initial states, exit 2") {
  TemporaryFolder folder;
  ::setenv("NONSEP_CACHE_DIR", (folder / "cache").string().c_str(), 1);
  // d dT0/dp1 = 2 but d dT1/dp0 = 0: no T has this gradient.
  const json formula = {{"name", "not_a_gradient"}, {"dT", {"p0 + 2*p1", "p1"}}, {"V", "q0^2/2 + q1^2/2"}};
  const auto file = write_job(
      folder / "job.json",
      run_job_with({{"formula", formula}}, {{"q", {0.5, 0.1}}, {"p", {0.25, 0.3}}}, {{"dt", 0.01}, {"steps", 10}}));
  const auto result = run_compiling({"run", "--quiet", "-o", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  CHECK(result.status == 2);
  CHECK(contains(result.err, "/model/formula/dT: found the Jacobian of dT at initial state 0"));
  CHECK(contains(result.err, "d dT[1] / dp0 = 0"));
  CHECK(contains(result.err, "is not the gradient of any function"));
  CHECK(!fs::exists(folder / "out" / "summary.json"));
  ::unsetenv("NONSEP_CACHE_DIR");
}

TEST_CASE("formula gradients: coupled Tao oscillators with c = 1/2 run off with bounded energy and are told so") {
  TemporaryFolder folder;
  ::setenv("NONSEP_CACHE_DIR", (folder / "cache").string().c_str(), 1);
  // On q0 = -q1 with p0 = p1, H = (1 + p0^2)(1 + (1 - 2c) s^2): flat in s at c = 1/2 (docs/method.md).
  const json formula = {
      {"name", "coupled_tao_shell"},
      {"T", "(p0*sqrt(1 + p0^2) + asinh(p0))/(2*sqrt(2)) + (p1*sqrt(1 + p1^2) + asinh(p1))/(2*sqrt(2))"},
      {"V", "q0^2/2 + q0^4/12 + q1^2/2 + q1^4/12 + c*q0^2*q1^2"},
      {"parameters", {{"c", 0.2}}}};
  json job = run_job_with({{"formula", formula}, {"parameters", {{"c", 0.5}}}}, {{"q", {0.3, -0.3}}, {"p", {0.6, 0.6}}},
                          {{"dt", 0.002}, {"t_end", 200}});
  job["output"] = {{"every", 0}, {"energy_every", 500}};
  const auto file = write_job(folder / "job.json", job);
  const auto result = run_compiling({"run", "-o", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  CHECK(contains(result.err, "after running off: max(|q_i|, |p_i|) grew from 0.6"));
  CHECK(contains(result.err, "the energy shell may be non-compact (docs/method.md, \"Non-compact energy shells\")"));
  CHECK(!contains(result.err, "use a smaller dt"));

  // The same orbit at c = 0.2 stays on its compact shell: no warning.
  job["model"]["parameters"]["c"] = 0.2;
  const auto compact_file = write_job(folder / "compact.json", job);
  const auto compact = run_nonsep({"run", "-o", (folder / "compact").string(), compact_file.string()}, folder.path());
  INFO("stderr (c = 0.2): " << compact.err);
  CHECK(compact.status == 0);
  CHECK(!contains(compact.err, "non-compact"));
  ::unsetenv("NONSEP_CACHE_DIR");
}

}  // namespace test_formula_gradients
