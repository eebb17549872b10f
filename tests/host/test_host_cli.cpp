// The built `nonsep` executable on job files, checked against independent numbers: the exact end point of the
// paper's 1D test, the core run directly on the paper1d plugin's model class compiled in (bit for bit) and on the
// tests' hand-written Paper1D (to rounding), ensemble against single runs, and the behaviour on divergence,
// plugin failure, missing Hessians and SIGINT.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "paper1d/paper1d.hpp"
#include "support/models.hpp"
#include "support/nan_aware.hpp"
#include "nonsep/core.hpp"
#include "nonsep/reference/paper1d_exact.hpp"

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

constexpr double quarter_period = 0.3863765573361232;

struct CoreRun {
  nonsep::PhaseSpaceBatch state;
  nonsep::EvaluationCounts evaluations;
};

// The paper1d plugin's own model class (plugins/paper1d/paper1d.hpp) behind the SDK's batched adapter, compiled
// into this test: the same arithmetic as the plugin the host loads, so results must agree bit for bit.
using PluginPaper1D = nonsep::sdk::ModelAdapter<::Paper1D>;

// The core on its own: `steps` steps of dt from (q0, p0) on `model`. dt goes through a volatile so that the
// compiler cannot fold cbrt(dt) for a literal dt: folding rounds correctly, which can differ in the last bit from
// the run-time cbrt the host uses.
template <class M = PluginPaper1D>
CoreRun core_run(const nonsep::IntegratorSpec& spec, double q0, double p0, double literal_dt, std::uint64_t steps,
                 const M& model = M{}) {
  volatile double opaque_dt = literal_dt;
  const double dt = opaque_dt;
  nonsep::Integrator integrator(spec);
  const double q[] = {q0}, p[] = {p0};
  CoreRun run{nonsep::PhaseSpaceBatch::single(q, p), {}};
  for (std::uint64_t k = 0; k < steps; ++k) integrator.step(model, run.state, dt);
  run.evaluations = integrator.evaluations();
  return run;
}

nonsep::IntegratorSpec triplet_43(double t2 = -2.0) { return {"triplet", nonsep::Fraction(4, 3), t2}; }

// Runs `job` (written to folder/name.json) with --output folder/name and returns the summary.
json run_job(const TemporaryFolder& folder, const std::string& name, const json& job, int expected_status = 0) {
  const auto file = write_job(folder / (name + ".json"), job);
  const auto result = run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == expected_status);
  return read_json(folder / name / "summary.json");
}

double number(const json& value) { return value.get<double>(); }

json paper1d_job(json initial, json time, json integrator = {{"scheme", "triplet"}, {"order", "4/3"}, {"t2", -2.0}}) {
  return {{"model", {{"plugin", "paper1d"}}},
          {"integrator", std::move(integrator)},
          {"initial", std::move(initial)},
          {"time", std::move(time)},
          {"output", {{"every", 1}}}};
}

json blowup_job(json initial, json parameters = json::object(), std::string plugin = "blowup") {
  return {{"model", {{"plugin", std::move(plugin)}, {"parameters", std::move(parameters)}}},
          {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
          {"initial", std::move(initial)},
          {"time", {{"dt", 0.001}, {"steps", 40}}},
          {"output", {{"every", 5}}}};
}

json state(double q, double p) { return {{"q", {q}}, {"p", {p}}}; }

}  // namespace

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
    json job = paper1d_job(state(q0, 0.25), {{"dt", 0.01}, {"steps", 25}},
                           {{"scheme", c.scheme}, {"order", c.order}});
    job["hamiltonian"] = c.form;
    const json summary = run_job(folder, std::string(c.scheme) + "-" + c.form, job);
    nonsep::IntegratorSpec spec{c.scheme, nonsep::Fraction::parse(c.order)};
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
    const json single = run_job(folder, "single" + std::to_string(i), paper1d_job(state(starts[i].first, starts[i].second), time));
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
        3 * run_job(folder, "single0-again", paper1d_job(state(0.5, 0.0), time))["evaluations"]["grad_T"].get<std::uint64_t>());
}

TEST_CASE("a grid job runs its states in the documented order") {
  TemporaryFolder folder;
  const json job = paper1d_job({{"grid", {{"q", {{{"from", 1.0}, {"to", 2.0}, {"count", 2}}}}, {"p", {{{"values", {0.0, 0.5}}}}}}}},
                               {{"dt", 0.01}, {"steps", 10}});
  const json summary = run_job(folder, "grid", job);
  REQUIRE(summary["trajectories"].size() == 4);
  const std::vector<std::pair<double, double>> expected{{1.0, 0.0}, {1.0, 0.5}, {2.0, 0.0}, {2.0, 0.5}};
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(number(summary["trajectories"][i]["initial"]["q"][0]) == expected[i].first);
    CHECK(number(summary["trajectories"][i]["initial"]["p"][0]) == expected[i].second);
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

TEST_CASE("a diverging trajectory stops with its step, time and variable, the others continue unchanged, exit 1") {
  TemporaryFolder folder;
  // grad V = q^3 overflows for |q| > 5.6e102: the middle state turns non-finite in its first step.
  const json list = json::array({state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)});
  const json summary = run_job(folder, "diverging", blowup_job(list), 1);
  CHECK(summary["status"] == "diverged");
  const json& diverged = summary["trajectories"][1];
  CHECK(diverged["status"] == "diverged");
  CHECK(diverged["diverged"]["step"] == 1);
  CHECK(number(diverged["diverged"]["t"]) == 0.001);
  const std::string variable = diverged["diverged"]["variable"];
  CHECK((variable == "q[0]" || variable == "p[0]"));
  CHECK(diverged["final"]["step"] == 0);
  CHECK(number(diverged["final"]["q"][0]) == 1e103);
  CHECK(summary["counts"]["completed"] == 2);

  const json survivors = run_job(folder, "survivors", blowup_job(json::array({state(1.0, 0.5), state(-0.5, 0.25)})));
  CHECK(summary["trajectories"][0]["final"] == survivors["trajectories"][0]["final"]);
  CHECK(summary["trajectories"][2]["final"] == survivors["trajectories"][1]["final"]);
  CHECK(summary["trajectories"][2]["energy"] == survivors["trajectories"][1]["energy"]);

  // Everything written stays valid: the diverged trajectory's rows end with its last finite state.
  const auto rows = read_csv(folder / "diverging" / "trajectory.csv");
  std::size_t rows_of_1 = 0;
  for (const auto& row : rows)
    if (row[0] == "1") {
      ++rows_of_1;
      CHECK(row[1] == "0");
      for (std::size_t c = 2; c < row.size(); ++c)
        if (!row[c].empty()) CHECK(std::isfinite(std::stod(row[c])));
    }
  CHECK(rows_of_1 == 1);
}

TEST_CASE("a plugin failing mid-run fails that trajectory with the plugin's message, the others complete, exit 1") {
  TemporaryFolder folder;
  // fail_above = 3: grad V refuses |q| > 3, which the second state starts beyond.
  const json list = json::array({state(1.0, 0.5), state(5.0, 0.0), state(-0.5, 0.25)});
  const auto file = write_job(folder / "failing.json", blowup_job(list, {{"fail_above", 3.0}}));
  const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.err.find("trajectory 1 failed") != std::string::npos);
  const json summary = read_json(folder / "failing.out" / "summary.json");
  CHECK(summary["status"] == "failed");
  CHECK(summary["trajectories"][1]["status"] == "failed");
  CHECK(summary["trajectories"][1]["error"].get<std::string>().find("beyond fail_above") != std::string::npos);
  CHECK(summary["trajectories"][0]["status"] == "completed");
  CHECK(summary["trajectories"][2]["status"] == "completed");
  const json survivors = run_job(folder, "survivors", blowup_job(json::array({state(1.0, 0.5), state(-0.5, 0.25)})));
  CHECK(summary["trajectories"][0]["final"] == survivors["trajectories"][0]["final"]);
  CHECK(summary["trajectories"][2]["final"] == survivors["trajectories"][1]["final"]);
}

TEST_CASE("without Hessians the energy is null, the CSV's energy cells empty, and the summary says why") {
  TemporaryFolder folder;
  const json summary = run_job(folder, "no-energy", blowup_job(state(1.0, 0.5), json::object(), "blowup_gradients_only"));
  CHECK(summary["status"] == "completed");
  CHECK(summary["energy"]["available"] == false);
  CHECK(summary["energy"]["reason"].get<std::string>().find("Hessians") != std::string::npos);
  CHECK(summary["trajectories"][0]["energy"]["initial"].is_null());
  CHECK(summary["trajectories"][0]["energy"]["relative_error_max_abs"].is_null());
  const json with_energy = run_job(folder, "energy", blowup_job(state(1.0, 0.5)));
  CHECK(summary["trajectories"][0]["final"] == with_energy["trajectories"][0]["final"]);
  CHECK(number(with_energy["trajectories"][0]["energy"]["initial"]) == 0.75);  // 3 q^2 p^2
  for (const auto& row : read_csv(folder / "no-energy" / "trajectory.csv")) {
    REQUIRE(row.size() == 7);
    if (row[0] == "trajectory") continue;
    CHECK(row[5].empty());
    CHECK(row[6].empty());
  }
}

TEST_CASE("SIGINT: the run finishes its step, writes its outputs with status interrupted and exits 130") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["time"] = {{"dt", 1e-6}, {"steps", 1000000000000}};
  job["output"] = {{"directory", "out"}, {"every", 1000}};
  const auto file = write_job(folder / "long.json", job);
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  const auto csv = folder / "out" / "trajectory.csv";
  for (int i = 0; i < 400 && !(std::filesystem::exists(csv) && read_text(csv).size() > 2000); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  REQUIRE(::kill(process.pid, SIGINT) == 0);
  const auto result = finish(process, std::chrono::seconds(30));
  INFO("stderr: " << result.err);
  CHECK(result.status == 130);
  const json summary = read_json(folder / "out" / "summary.json");
  CHECK(summary["status"] == "interrupted");
  const auto completed = summary["time"]["steps_completed"].get<std::uint64_t>();
  CHECK(completed > 0);
  CHECK(summary["trajectories"][0]["status"] == "interrupted");
  CHECK(summary["trajectories"][0]["final"]["step"] == completed);
  const auto rows = read_csv(csv);
  CHECK(rows.back()[1] == std::to_string(completed));
  const CoreRun core = core_run(triplet_43(), 2.0, 0.0, 1e-6, completed);
  CHECK(number(summary["trajectories"][0]["final"]["q"][0]) == core.state.q()[0]);
}

TEST_CASE("the default output folder is <job>.out beside the job file, --output overrides it") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job.erase("output");
  const auto file = write_job(folder / "orbit.json", job);
  CHECK(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  CHECK(std::filesystem::exists(folder / "orbit.out" / "summary.json"));
  CHECK(std::filesystem::exists(folder / "orbit.out" / "trajectory.csv"));
  job["output"] = {{"directory", "results/a"}};
  write_job(file, job);
  CHECK(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  CHECK(std::filesystem::exists(folder / "results" / "a" / "summary.json"));
  // Only summary.json and trajectory.csv: the temporary file of the atomic write is gone.
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder / "results" / "a")) {
    CHECK((entry.path().filename() == "summary.json" || entry.path().filename() == "trajectory.csv"));
    ++files;
  }
  CHECK(files == 2);
}

TEST_CASE("an output folder that cannot be created is invalid input: exit 2") {
  TemporaryFolder folder;
  write_text(folder / "blocker", "a file, not a folder");
  const auto file = write_job(folder / "job.json", quickstart_job());
  const auto result = run_nonsep({"run", "--quiet", "--output", (folder / "blocker" / "out").string(), file.string()},
                                 folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("blocker") != std::string::npos);
}

TEST_CASE("validate checks without running, errors go to stderr with exit 2") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", quickstart_job());
  auto result = run_nonsep({"validate", file.string()}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("valid:") != std::string::npos);
  CHECK(result.out.find("78 steps") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(folder / "quickstart.out"));
  json job = quickstart_job();
  job["model"] = {{"plugin", "radial"}, {"parameters", {{"dimension", 3}}}};
  write_job(file, job);
  result = run_nonsep({"validate", file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("/initial/q: found 1 components") != std::string::npos);
}

TEST_CASE("usage: --version, --help with the schemes, options and exit statuses, usage errors exit 2") {
  TemporaryFolder folder;
  auto result = run_nonsep({"--version"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.rfind("nonsep ", 0) == 0);
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--help"}, {"run", "--help"}}) {
    result = run_nonsep(args, folder.path());
    CHECK(result.status == 0);
    for (const auto& scheme : nonsep::scheme_catalogue()) {
      CHECK(result.out.find("  " + scheme.name + ": " + scheme.method) != std::string::npos);
      for (const auto& parameter : scheme.parameters)
        CHECK(result.out.find(parameter.name + " (default " + parameter.default_text + ")") != std::string::npos);
    }
    for (const char* status : {"  0 ", "  1 ", "  2 ", "  130 "}) CHECK(result.out.find(status) != std::string::npos);
  }
  for (const std::vector<std::string>& args : {std::vector<std::string>{}, {"run"}, {"frobnicate"}, {"run", "a", "b"},
                                              {"inspect", "paper1d", "--nope"}}) {
    CHECK(run_nonsep(args, folder.path()).status == 2);
  }
  const auto unknown = run_nonsep({"frobnicate", "job.json"}, folder.path());
  CHECK(unknown.err.find("unknown command 'frobnicate'; the commands are run, validate, inspect and models") !=
        std::string::npos);
}

TEST_CASE("models lists every plugin on the search path, one line each") {
  TemporaryFolder folder;
  const auto result = run_nonsep({"models"}, folder.path());
  CHECK(result.status == 0);
  for (const char* name : {"paper1d", "radial", "quadratic_kinetic", "tao_product", "blowup", "blowup_gradients_only"}) {
    CAPTURE(name);
    const auto at = result.out.find(std::string(name) + "  ");
    REQUIRE(at != std::string::npos);
    const auto line = result.out.substr(at, result.out.find('\n', at) - at);
    CHECK(line.find(std::string(name) + ".so") != std::string::npos);
    CHECK(line.find("dimension") != std::string::npos);
  }
}

TEST_CASE("inspect shows the metadata, --json the raw metadata, --check the derivative check") {
  TemporaryFolder folder;
  auto result = run_nonsep({"inspect", "radial"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("dimension integer 2") != std::string::npos);
  CHECK(result.out.find("[1, 16]") != std::string::npos);

  result = run_nonsep({"inspect", "paper1d", "--json"}, folder.path());
  CHECK(result.status == 0);
  CHECK(json::parse(result.out)["name"] == "paper1d");

  for (const char* good : {"paper1d", "radial", "blowup"}) {
    CAPTURE(good);
    result = run_nonsep({"inspect", good, "--check"}, folder.path());
    CHECK(result.status == 0);
    CHECK(result.out.find("derivative check passed") != std::string::npos);
  }
  result = run_nonsep({"inspect", "blowup_wrong_hessian", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("derivative check FAILED") != std::string::npos);
  CHECK(result.out.find("  hessian_V[0] at (") != std::string::npos);

  result = run_nonsep({"inspect", "no_such_plugin"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("no_such_plugin") != std::string::npos);
}

namespace {

// The largest |relative_energy_error| over the rows of a trajectory.csv (the numbers round-trip exactly).
double largest_csv_energy_error(const std::filesystem::path& csv) {
  double largest = 0.0;
  for (const auto& row : read_csv(csv))
    if (row[0] != "trajectory" && !row.back().empty())
      largest = nonsep::testing::max_or_nan(largest, std::abs(std::stod(row.back())));
  return largest;
}

// summary.json without what legitimately differs between two runs of one job: the time taken and the folder.
json comparable(json summary) {
  summary.erase("wall_seconds");
  summary["output"].erase("directory");
  return summary;
}

}  // namespace

TEST_CASE("energy: H at step 0, the samples, every energy_every-th step and the end; max_abs over exactly those") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["time"] = {{"dt", 0.005}, {"steps", 120}};  // past the quarter period: the error is largest mid-run
  job["output"] = {{"every", 1}};
  const json all = run_job(folder, "every1", job);
  const json& all_energy = all["trajectories"][0]["energy"];
  CHECK(number(all_energy["relative_error_max_abs"]) == largest_csv_energy_error(folder / "every1" / "trajectory.csv"));
  CHECK(all["energy"]["relative_error_max_abs"].get<std::string>().find("where H was evaluated") != std::string::npos);

  job["output"] = {{"every", 0}, {"energy_every", 1}};
  const json strided = run_job(folder, "energy_every1", job);
  CHECK(strided["output"]["energy_every"] == 1);
  CHECK(strided["trajectories"][0]["energy"] == all_energy);
  CHECK(strided["trajectories"][0]["final"] == all["trajectories"][0]["final"]);

  job["output"] = {{"every", 0}};
  const json ends = run_job(folder, "ends_only", job);
  const json& ends_energy = ends["trajectories"][0]["energy"];
  CHECK(ends_energy["final"] == all_energy["final"]);
  CHECK(number(ends_energy["relative_error_max_abs"]) == std::abs(number(ends_energy["relative_error_final"])));
  CHECK(number(ends_energy["relative_error_max_abs"]) < number(all_energy["relative_error_max_abs"]));

  job["output"] = {{"every", 10}};
  const json sampled = run_job(folder, "every10", job);
  CHECK(number(sampled["trajectories"][0]["energy"]["relative_error_max_abs"]) ==
        largest_csv_energy_error(folder / "every10" / "trajectory.csv"));
  CHECK(sampled["trajectories"][0]["final"] == all["trajectories"][0]["final"]);
}

TEST_CASE("threads: 1, 2 and 3 threads write byte-identical trajectory.csv and summary.json (but wall_seconds)") {
  TemporaryFolder folder;
  use_test_plugins();
  // 600 trajectories: three blocks of run_block_size = 256. A diverging state in the first block and, in the
  // second job, a failing state in the last block make blocks replay their chunk step by step.
  json diverging = json::array(), failing = json::array(), completing = json::array();
  for (int i = 0; i < 600; ++i) {
    const double q = 0.5 + 0.001 * i;
    diverging.push_back(i == 100 ? state(1e103, 1.0) : state(q, 0.25));
    failing.push_back(i == 550 ? state(5.0, 0.0) : state(q, 0.25));
    completing.push_back(state(q, 0.25));
  }
  for (const auto& [name, job, expected] : {std::tuple{"diverging", blowup_job(diverging), 1},
                                            std::tuple{"failing", blowup_job(failing, {{"fail_above", 3.0}}), 1},
                                            std::tuple{"paper1d", paper1d_job(completing, {{"dt", 0.002}, {"steps", 30}}), 0}}) {
    const std::string job_name = name;
    CAPTURE(job_name);
    const auto file = write_job(folder / (std::string(name) + ".json"), job);
    std::vector<std::string> csv;
    std::vector<json> summaries;
    for (const char* threads : {"1", "2", "3"}) {
      const auto out = folder / (std::string(name) + "-" + threads);
      const auto result =
          run_nonsep({"run", "--quiet", "--threads", threads, "--output", out.string(), file.string()}, folder.path());
      CHECK(result.status == expected);
      csv.push_back(read_text(out / "trajectory.csv"));
      summaries.push_back(comparable(read_json(out / "summary.json")));
    }
    CHECK(summaries[0]["trajectories"].size() == 600);
    CHECK(csv[0].size() > 10000);
    CHECK(csv[1] == csv[0]);
    CHECK(csv[2] == csv[0]);
    CHECK(summaries[1] == summaries[0]);
    CHECK(summaries[2] == summaries[0]);
  }
}

TEST_CASE("--threads must be a whole number from 1 to 4096") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", quickstart_job());
  const auto zero = run_nonsep({"run", "--threads", "0", file.string()}, folder.path());
  CHECK(zero.status == 2);
  CHECK(zero.err.find("--threads: Value 0 not in range 1 to 4096") != std::string::npos);
  CHECK(run_nonsep({"run", "--threads", "two", file.string()}, folder.path()).status == 2);
}

TEST_CASE("closest_return is the same whether the run steps in chunks (every = 0) or sample by sample, and on a replay") {
  TemporaryFolder folder;
  use_test_plugins();
  // Blowup with a diverging middle state: the block replays its first chunk step by step.
  json job = blowup_job(json::array({state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)}));
  job["analysis"] = {{"closest_return_after", 0.01}};
  job["time"] = {{"dt", 0.001}, {"steps", 400}};
  job["output"] = {{"every", 1}};
  const json sampled = run_job(folder, "sampled", job, 1);
  job["output"] = {{"every", 0}};
  const json chunked = run_job(folder, "chunked", job, 1);
  for (std::size_t i : {0u, 2u}) {
    CAPTURE(i);
    REQUIRE(sampled["trajectories"][i]["closest_return"].is_object());
    CHECK(chunked["trajectories"][i]["closest_return"] == sampled["trajectories"][i]["closest_return"]);
    CHECK(chunked["trajectories"][i]["final"] == sampled["trajectories"][i]["final"]);
  }
  CHECK(chunked["trajectories"][1]["closest_return"] == sampled["trajectories"][1]["closest_return"]);
}

namespace {

// The fenced code blocks of README.md's section `heading` (up to the next heading of the same or a higher level),
// each as (language, text).
std::vector<std::pair<std::string, std::string>> readme_code_blocks(const std::string& heading) {
  const std::string readme = read_text(std::filesystem::path(NONSEP_SOURCE_DIR) / "README.md");
  const auto start = readme.find("\n" + heading + "\n");
  REQUIRE(start != std::string::npos);
  const auto level = heading.find(' ');
  auto end = std::string::npos;
  for (std::size_t hashes = 1; hashes <= level; ++hashes) {
    std::string marker(1, '\n');  // appended, not "\n" + ...: GCC 12 warns falsely (-Wrestrict) about that
    marker.append(hashes, '#').push_back(' ');
    end = std::min(end, readme.find(marker, start + 1));
  }
  std::istringstream section(readme.substr(start, end - start));
  std::vector<std::pair<std::string, std::string>> blocks;
  std::string line;
  bool inside = false;
  while (std::getline(section, line)) {
    if (line.rfind("```", 0) == 0) {
      if (!inside) blocks.emplace_back(line.substr(3), "");
      inside = !inside;
    } else if (inside) {
      blocks.back().second += line + "\n";
    }
  }
  return blocks;
}

}  // namespace

TEST_CASE("README: the worked example shows the quickstart's job, command line, summary.json and rows as they are") {
  const auto blocks = readme_code_blocks("### A worked example");
  REQUIRE(blocks.size() == 4);
  REQUIRE(blocks[0].first == "json");
  REQUIRE(blocks[1].first == "console");
  REQUIRE(blocks[2].first == "json");
  REQUIRE(blocks[3].first == "text");

  // The job: the file itself, but for the description the README shortens.
  json shown_job = json::parse(blocks[0].second);
  json job = quickstart_job();
  shown_job.erase("description");
  job.erase("description");
  CHECK(shown_job == job);

  // The command line, run from the repository root as shown.
  TemporaryFolder folder;
  const auto file = write_job(folder / "quickstart.json", quickstart_job());
  const auto result = run_nonsep({"run", file.string()}, folder.path());
  REQUIRE(result.status == 0);
  const std::string shown_line = blocks[1].second.substr(blocks[1].second.find('\n') + 1);
  const std::string machine_part = "results in ";
  const auto cut = shown_line.find(machine_part);
  REQUIRE(cut != std::string::npos);
  CHECK(result.out.substr(0, cut) == shown_line.substr(0, cut));

  // summary.json: everything but what depends on where and when it ran.
  json shown = json::parse(blocks[2].second);
  json summary = read_json(folder / "quickstart.out/summary.json");
  for (json* document : {&shown, &summary}) {
    document->erase("job");
    document->erase("wall_seconds");
    (*document)["model"].erase("path");
    (*document)["output"].erase("directory");
  }
  CHECK(shown == summary);

  // trajectory.csv: every row shown is a row of the file, and the first and last rows are where the README says.
  const std::string csv = read_text(folder / "quickstart.out/trajectory.csv");
  std::istringstream rows(blocks[3].second);
  std::string row;
  std::vector<std::string> shown_rows;
  while (std::getline(rows, row))
    if (row != "...") shown_rows.push_back(row);
  REQUIRE(shown_rows.size() >= 3);
  CHECK(csv.rfind(shown_rows.front() + "\n", 0) == 0);
  CHECK(csv.size() >= shown_rows.back().size() + 1);
  CHECK(csv.substr(csv.size() - shown_rows.back().size() - 1) == shown_rows.back() + "\n");
  for (const auto& shown_row : shown_rows) {
    CAPTURE(shown_row);
    CHECK(csv.find(shown_row + "\n") != std::string::npos);
  }
}

TEST_CASE("README: the example of errors in a job file is what `nonsep validate` prints") {
  const auto blocks = readme_code_blocks("### Errors in job files");
  REQUIRE(!blocks.empty());
  REQUIRE(blocks[0].first == "console");
  const std::string& shown = blocks[0].second;
  const std::string prompt = "$ nonsep validate ";
  REQUIRE(shown.rfind(prompt, 0) == 0);
  const auto command_end = shown.find('\n');
  const std::string job = shown.substr(prompt.size(), command_end - prompt.size());
  const std::string absolute = (std::filesystem::path(NONSEP_SOURCE_DIR) / job).string();
  TemporaryFolder folder;
  auto result = run_nonsep({"validate", absolute}, folder.path());
  CHECK(result.status == 2);
  result.err.replace(result.err.find(absolute), absolute.size(), job);  // as run from the repository's root
  CHECK(result.err == shown.substr(command_end + 1));
}

TEST_CASE("many trajectories stop: stderr names the first 20 and says how many more summary.json lists") {
  TemporaryFolder folder;
  json initial = json::array();
  for (int k = 0; k < 25; ++k) initial.push_back(state(1e103, 0.0));  // grad V = q^3 overflows in the first step
  initial.push_back(state(0.5, 0.5));
  const auto file = write_job(folder / "many.json", blowup_job(initial));
  const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(result.status == 1);
  std::size_t lines = 0;
  for (std::size_t at = 0; (at = result.err.find("nonsep: trajectory ", at)) != std::string::npos; ++at) ++lines;
  CHECK(lines == 20);
  CHECK(result.err.find("nonsep: trajectory 19 diverged at step 1") != std::string::npos);
  CHECK(result.err.find("nonsep: trajectory 20 ") == std::string::npos);
  CHECK(result.err.find("... and 5 more trajectories that diverged or failed; ") != std::string::npos);
  CHECK(read_json(folder / "many.out/summary.json")["counts"]["diverged"] == 25);
}
