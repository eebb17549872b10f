// The built `nonsep` executable on job files, checked against independent numbers: the exact end point of the
// paper's 1D test, the core run directly on the paper1d plugin's model class compiled in (bit for bit) and on the
// tests' hand-written Paper1D (to rounding), the measured order through the host, samples, ensembles against single
// runs, grids and time reversibility.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "support/models.hpp"

namespace test_host_run {

using nlohmann::json;
using namespace nonsep::host_testing;

TEST_CASE("quickstart: the exact quarter period, the end point of the paper's 1D test within the method's error") {
  const auto exact = nonsep::reference::paper1d_quarter(2.0);
  CHECK(exact.period == doctest::Approx(quarter_period).epsilon(1e-15));
  CHECK(quickstart_job()["time"]["t_end"] == quarter_period);

  TemporaryFolder folder;
  const json summary = run_job(folder, "quickstart", quickstart_job());
  CHECK(summary["status"] == "completed");
  CHECK(summary["model"]["plugin"] == "paper1d");
  CHECK(summary["model"]["dimension"] == 1);
  CHECK(summary["hamiltonian"] == "TTV");
  CHECK(summary["integrator"]["scheme"] == "triplet");
  CHECK(summary["integrator"]["order"] == "4/3");
  CHECK(summary["integrator"]["t2"] == -2.0);
  CHECK(summary["integrator"]["symplectic"] == true);
  CHECK(summary["integrator"]["basic_steps_per_step"] == 3);
  CHECK(summary["time"]["steps"] == 78);
  CHECK(number(summary["time"]["dt"]) == quarter_period / 78.0);
  CHECK(summary["time"]["t_end"] == quarter_period);

  const json& trajectory = summary["trajectories"][0];
  CHECK(trajectory["status"] == "completed");
  CHECK(trajectory["final"]["t"] == quarter_period);
  CHECK(trajectory["final"]["step"] == 78);
  const double q = number(trajectory["final"]["q"][0]), p = number(trajectory["final"]["p"][0]);
  // Triplet 4/3 with dt ~ 0.005 and t2 = -2 (the paper's Fig. 3 setting): errors of a few 1e-3 in q, 1e-2 in p.
  CHECK(std::abs(q - 0.0) < 5e-3);
  CHECK(std::abs(p - exact.p_final) < 5e-2);
  CHECK(number(trajectory["energy"]["initial"]) == 5.0);
  const double energy = nonsep::testing::Paper1D::H_TTV(q, p);
  CHECK(number(trajectory["energy"]["final"]) == doctest::Approx(energy).epsilon(1e-14));
  CHECK(number(trajectory["energy"]["relative_error_final"]) == doctest::Approx((energy - 5.0) / 5.0).epsilon(1e-12));
  CHECK(number(trajectory["energy"]["relative_error_max_abs"]) >=
        std::abs(number(trajectory["energy"]["relative_error_final"])));
}

TEST_CASE("quickstart: the host's final state and evaluation counts equal the core's, bit for bit") {
  TemporaryFolder folder;
  const json summary = run_job(folder, "quickstart", quickstart_job());
  const CoreRun core = core_run(triplet_43(), 2.0, 0.0, quarter_period / 78.0, 78);
  const json& final_state = summary["trajectories"][0]["final"];
  CHECK(number(final_state["q"][0]) == core.state.q()[0]);
  CHECK(number(final_state["p"][0]) == core.state.p()[0]);
  CHECK(summary["evaluations"]["grad_T"] == core.evaluations.grad_T);
  CHECK(summary["evaluations"]["grad_V"] == core.evaluations.grad_V);
  // 78 steps x 3 basic steps x 4 gradients of each kind, plus the first-same-as-last gradient at the start.
  CHECK(core.evaluations.grad_T == 78 * 3 * 4);
  CHECK(core.evaluations.grad_V == 78 * 3 * 4 + 1);
  // The tests' own Paper1D writes grad V as q + q^3/3 instead of the plugin's q (1 + q^2/3): equal to rounding.
  const CoreRun hand_written = core_run(triplet_43(), 2.0, 0.0, quarter_period / 78.0, 78, nonsep::testing::Paper1D{});
  CHECK(number(final_state["q"][0]) == doctest::Approx(hand_written.state.q()[0]).epsilon(1e-12));
  CHECK(number(final_state["p"][0]) == doctest::Approx(hand_written.state.p()[0]).epsilon(1e-12));
}

TEST_CASE("every scheme and both Hamiltonian forms agree with the core bit for bit") {
  TemporaryFolder folder;
  struct Case {
    const char* scheme;
    const char* order;
    const char* form;
  };
  for (const Case c : {Case{"basic", "2/3", "TTV"}, Case{"triplet", "2", "TTV"}, Case{"mpe", "2", "TTV"},
                       Case{"mpe", "4/3", "VVT"}, Case{"triplet", "4/3", "VVT"}}) {
    // H_VVT = (q + q^3/3)^2 p is unbounded below; (0.5, 0.25) stays tame over these 25 steps.
    const double q0 = std::string(c.form) == "VVT" ? 0.5 : 1.5;
    const std::string scheme = c.scheme, order = c.order, form = c.form;
    CAPTURE(scheme);
    CAPTURE(order);
    CAPTURE(form);
    json job = paper1d_job(state(q0, 0.25), {{"dt", 0.01}, {"steps", 25}}, {{"scheme", c.scheme}, {"order", c.order}});
    job["hamiltonian"] = c.form;
    const json summary = run_job(folder, std::string(c.scheme) + "-" + c.form, job);
    nonsep::IntegratorSpec spec{c.scheme, nonsep::ChinOptions{nonsep::Fraction::parse(c.order)}};
    spec.form = std::string(c.form) == "VVT" ? nonsep::HamiltonianForm::VVT : nonsep::HamiltonianForm::TTV;
    const CoreRun core = core_run(spec, q0, 0.25, 0.01, 25);
    CHECK(number(summary["trajectories"][0]["final"]["q"][0]) == core.state.q()[0]);
    CHECK(number(summary["trajectories"][0]["final"]["p"][0]) == core.state.p()[0]);
    CHECK(summary["integrator"]["symplectic"] == (std::string(c.scheme) != "mpe"));
    const double q = core.state.q()[0], p = core.state.p()[0];
    const double energy = spec.form == nonsep::HamiltonianForm::TTV ? nonsep::testing::Paper1D::H_TTV(q, p)
                                                                    : nonsep::testing::Paper1D::H_VVT(q, p);
    CHECK(number(summary["trajectories"][0]["energy"]["final"]) == doctest::Approx(energy).epsilon(1e-13));
  }
}

TEST_CASE("through the host, triplet 4/3 converges at order 4/3 to the exact quarter-period end point") {
  TemporaryFolder folder;
  const auto exact = nonsep::reference::paper1d_quarter(2.0);
  std::vector<double> errors;
  for (const std::uint64_t steps : {100, 400}) {
    const json summary =
        run_job(folder, "steps" + std::to_string(steps),
                paper1d_job(state(2.0, 0.0), {{"dt", exact.period / static_cast<double>(steps)}, {"steps", steps}}));
    errors.push_back(std::abs(number(summary["trajectories"][0]["final"]["p"][0]) - exact.p_final));
  }
  // Order 4/3: a 4 times smaller step shrinks the error 4^(4/3) = 6.35 times.
  const double observed_order = std::log(errors[0] / errors[1]) / std::log(4.0);
  CHECK(observed_order == doctest::Approx(4.0 / 3.0).epsilon(0.1));
}

TEST_CASE("trajectory.csv: samples at step 0, every `every` steps and the final step, matching the summary") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["output"]["every"] = 10;
  const json summary = run_job(folder, "every10", job);
  const auto rows = read_csv(folder / "every10" / "trajectory.csv");
  REQUIRE(rows.size() == 1 + 9);  // steps 0, 10, ..., 70, and 78
  CHECK(rows[0] == std::vector<std::string>{"trajectory", "step", "t", "q0", "p0", "H", "relative_energy_error"});
  CHECK(rows[1] == std::vector<std::string>{"0", "0", "0", "2", "0", "5", "0"});
  for (std::size_t i = 1; i < 9; ++i) CHECK(rows[i][1] == std::to_string(10 * (i - 1)));
  const auto& last = rows.back();
  CHECK(last[1] == "78");
  CHECK(std::stod(last[2]) == quarter_period);
  CHECK(std::stod(last[3]) == number(summary["trajectories"][0]["final"]["q"][0]));
  CHECK(std::stod(last[4]) == number(summary["trajectories"][0]["final"]["p"][0]));
  CHECK(std::stod(last[5]) == number(summary["trajectories"][0]["energy"]["final"]));

  job["output"]["every"] = 0;
  run_job(folder, "every0", job);
  CHECK_FALSE(std::filesystem::exists(folder / "every0" / "trajectory.csv"));
  CHECK(std::filesystem::exists(folder / "every0" / "summary.json"));
}

TEST_CASE("an ensemble gives each trajectory exactly the numbers of its single run") {
  TemporaryFolder folder;
  const std::vector<std::pair<double, double>> starts{{0.5, 0.0}, {1.0, 0.3}, {2.0, -0.4}};
  json list = json::array();
  for (const auto& [q, p] : starts) list.push_back(state(q, p));
  const json time = {{"dt", 0.004}, {"t_end", 0.5}};
  const json ensemble = run_job(folder, "ensemble", paper1d_job(list, time));
  CHECK(ensemble["trajectories"].size() == 3);
  const auto ensemble_rows = read_csv(folder / "ensemble" / "trajectory.csv");
  for (std::size_t i = 0; i < starts.size(); ++i) {
    CAPTURE(i);
    const json single =
        run_job(folder, "single" + std::to_string(i), paper1d_job(state(starts[i].first, starts[i].second), time));
    CHECK(ensemble["trajectories"][i]["final"] == single["trajectories"][0]["final"]);
    CHECK(ensemble["trajectories"][i]["energy"] == single["trajectories"][0]["energy"]);
    const auto single_rows = read_csv(folder / ("single" + std::to_string(i)) / "trajectory.csv");
    std::vector<std::vector<std::string>> mine;
    for (const auto& row : ensemble_rows)
      if (row[0] == std::to_string(i)) mine.push_back(std::vector<std::string>(row.begin() + 1, row.end()));
    REQUIRE(mine.size() == single_rows.size() - 1);
    for (std::size_t k = 0; k < mine.size(); ++k)
      CHECK(mine[k] == std::vector<std::string>(single_rows[k + 1].begin() + 1, single_rows[k + 1].end()));
  }
  // One batched call per stage: the ensemble costs 3 times the gradients of one run, in a third of the calls.
  CHECK(ensemble["evaluations"]["grad_T"].get<std::uint64_t>() ==
        3 * run_job(folder, "single0-again", paper1d_job(state(0.5, 0.0), time))["evaluations"]["grad_T"]
                .get<std::uint64_t>());
}

TEST_CASE("a grid job runs its states in the documented order") {
  TemporaryFolder folder;
  const json job =
      paper1d_job({{"grid", {{"q", {{{"from", 1.0}, {"to", 2.0}, {"count", 2}}}}, {"p", {{{"values", {0.0, 0.5}}}}}}}},
                  {{"dt", 0.01}, {"steps", 10}});
  const json summary = run_job(folder, "grid", job);
  REQUIRE(summary["trajectories"].size() == 4);
  const auto rows = read_csv(folder / "grid" / "trajectory.csv");  // step 0 first, in trajectory order
  REQUIRE(rows.size() > 5);
  const std::vector<std::pair<double, double>> expected{{1.0, 0.0}, {1.0, 0.5}, {2.0, 0.0}, {2.0, 0.5}};
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(rows[i + 1][0] == std::to_string(i));
    CHECK(rows[i + 1][1] == "0");
    CHECK(std::stod(rows[i + 1][3]) == expected[i].first);
    CHECK(std::stod(rows[i + 1][4]) == expected[i].second);
    const CoreRun core = core_run(triplet_43(), expected[i].first, expected[i].second, 0.01, 10);
    CHECK(number(summary["trajectories"][i]["final"]["q"][0]) == core.state.q()[0]);
  }
}

TEST_CASE("backwards in time: a negative dt retraces the quickstart to its start (time reversibility)") {
  TemporaryFolder folder;
  const json forward = run_job(folder, "forward", quickstart_job());
  const json& end = forward["trajectories"][0]["final"];
  json backward_job = quickstart_job();
  backward_job["initial"] = {{"q", end["q"]}, {"p", end["p"]}};
  backward_job["time"] = {{"dt", -0.005}, {"t_end", -quarter_period}};
  const json backward = run_job(folder, "backward", backward_job);
  CHECK(backward["time"]["steps"] == 78);
  CHECK(number(backward["time"]["dt"]) == -quarter_period / 78.0);
  CHECK(number(backward["trajectories"][0]["final"]["t"]) == -quarter_period);
  CHECK(number(backward["trajectories"][0]["final"]["q"][0]) == doctest::Approx(2.0).epsilon(1e-12));
  CHECK(std::abs(number(backward["trajectories"][0]["final"]["p"][0])) < 1e-11);
}

}  // namespace test_host_run
