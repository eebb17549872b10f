// Runs of models with a separable part K(p) + U(q) through the executable: the Mathews-Lakshmanan plugin ends
// where its exact solution does, summary.json counts grad_U (and grad_K for variable_mass2d), a run killed and
// resumed writes the same files bit for bit with the same counts, and Lyapunov exponents (tangent maps through
// the separable flows) run on variable_mass2d.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "host_run_support.hpp"
#include "nonsep/reference/mathews_lakshmanan_exact.hpp"

namespace test_host_separable {

using json = nlohmann::json;
using namespace nonsep::host_testing;

namespace {

json oscillator_job(json initial, json time, json integrator) {
  return {{"model", {{"plugin", "mathews_lakshmanan"}}},
          {"integrator", std::move(integrator)},
          {"initial", std::move(initial)},
          {"time", std::move(time)},
          {"output", {{"every", 1000}}}};
}

}  // namespace

TEST_CASE("mathews_lakshmanan through the host: the exact end state, the energy and the grad_U count") {
  const nonsep::reference::MathewsLakshmanan exact;
  const double period = exact.period(1.5);
  TemporaryFolder folder;
  const json summary = run_job(folder, "out",
                               oscillator_job(state(1.5, 0.0), {{"dt", period / 4000}, {"steps", 4000}},
                                              {{"scheme", "triplet"}, {"order", "2"}}));
  const json& end = summary["trajectories"][0];
  CAPTURE(end.dump());
  CHECK(std::abs(end["final"]["q"][0].get<double>() - 1.5) < 1e-6);
  CHECK(std::abs(end["final"]["p"][0].get<double>()) < 1e-4);  // order 2 at dt = T/4000: 3.1e-5
  CHECK(std::abs(end["energy"]["relative_error_final"].get<double>()) < 1e-7);
  // 4000 steps of 9 basic steps, each with two half-kicks by grad U.
  CHECK(summary["evaluations"]["grad_U"].get<std::uint64_t>() == 4000 * 9 * 2);
  CHECK(summary["evaluations"]["grad_K"].get<std::uint64_t>() == 0);
}

TEST_CASE("a separable model killed and resumed: the files and the evaluation counts bit for bit") {
  json initial = json::array();
  for (int k = 0; k < 200; ++k) initial.push_back(state(0.2 + 0.01 * k, 0.1));
  json job = oscillator_job(initial, {{"dt", 0.01}, {"steps", 60000}}, {{"scheme", "triplet"}, {"order", "4/3"}});
  job["checkpoint"] = {{"every_steps", 1000}, {"every_seconds", 0}};
  TemporaryFolder reference;
  const json uninterrupted = run_job(reference, "out", job);

  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", job);
  const auto step = kill_after_checkpoint(file, folder / "out", 20000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  REQUIRE(step < 60000);
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  for (const char* name : {"trajectory.csv", "trajectories.csv"}) {
    CAPTURE(name);
    CHECK(read_text(folder / "out" / name) == read_text(reference / "out" / name));
  }
  const json summary = read_run(folder / "out");
  CHECK(summary["evaluations"]["grad_U"] == uninterrupted["evaluations"]["grad_U"]);
  CHECK(summary["evaluations"]["grad_T"] == uninterrupted["evaluations"]["grad_T"]);
}

TEST_CASE("variable_mass2d: Lyapunov exponents through the separable flows' tangent maps, grad_K counted") {
  TemporaryFolder folder;
  const json job = {{"model", {{"plugin", "variable_mass2d"}}},
                    {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
                    {"initial", {{"q", {0.6, -0.4}}, {"p", {0.3, 0.2}}}},
                    {"time", {{"dt", 0.01}, {"steps", 2000}}},
                    {"output", {{"every", 500}}},
                    {"analysis", {{"lyapunov", json::object()}}}};
  const json summary = run_job(folder, "out", job);
  CHECK(summary["evaluations"]["grad_K"].get<std::uint64_t>() > 0);
  // The largest exponent estimate of the one trajectory, a finite number in trajectories.csv.
  const auto rows = read_csv(folder / "out" / "trajectories.csv");
  REQUIRE(rows.size() == 2);
  const auto column = std::find(rows[0].begin(), rows[0].end(), "lyapunov0");
  REQUIRE(column != rows[0].end());
  CHECK(std::isfinite(std::stod(rows[1][static_cast<std::size_t>(column - rows[0].begin())])));
}

}  // namespace test_host_separable
