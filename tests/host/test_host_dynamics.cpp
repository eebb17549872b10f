// The dynamics diagnostics end to end through the `nonsep` executable on paper2d (plugins/paper2d): Poincare
// sections (poincare.csv, crossings on the plane to round-off, max_crossings), Lyapunov exponents and MEGNO
// (trajectories.csv columns and lyapunov.csv), the same for any --threads, resumed bit for bit, the refusals, and a
// plugin failing while a crossing is located.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "host_run_support.hpp"
#include "paper2d/paper2d.hpp"

namespace test_host_dynamics {

using namespace nonsep::host_testing;

namespace {

using PluginPaper2D = nonsep::sdk::ModelAdapter<::Paper2D>;

const std::vector<double> regular_q{0.25, 0.3}, regular_p{-1.5, 0.2};  // quasi-periodic (plugins/paper2d)
const std::vector<double> chaotic_q{-0.75, 0.3}, chaotic_p{-1.5, 0.2};

// MPE of order 4 at dt = 0.005 keeps |H/H0 - 1| below 1e-4 on these orbits for t = 400 (the symplectic triplet 4/3
// with the default t2 diverges on the chaotic orbit at dt = 0.002: its error constant is large in 2D).
json paper2d_job(json initial, json time, json analysis) {
  return {{"model", {{"plugin", "paper2d"}}}, {"integrator", {{"scheme", "mpe"}, {"order", 4}}},
          {"initial", std::move(initial)},    {"time", std::move(time)},
          {"output", {{"every", 0}}},         {"analysis", std::move(analysis)}};
}

json state2(const std::vector<double>& q, const std::vector<double>& p) { return {{"q", q}, {"p", p}}; }

}  // namespace

TEST_CASE("poincare.csv: every crossing of q0 = 0 upwards lies on the plane to 1e-12, between its step's samples") {
  TemporaryFolder folder;
  json job = paper2d_job(json::array({state2(regular_q, regular_p), state2(chaotic_q, chaotic_p)}),
                         {{"dt", 0.005}, {"steps", 6000}}, {{"poincare", {{"component", "q0"}, {"value", 0.0}}}});
  job["output"]["every"] = 1;
  const auto result = run_named(folder, "run", job);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto crossings = table(folder / "run/poincare.csv");
  const auto samples = table(folder / "run/trajectory.csv");
  std::map<std::pair<int, int>, const std::map<std::string, std::string>*> by_step;
  for (const auto& row : samples) by_step[{int(cell(row, "trajectory")), int(cell(row, "step"))}] = &row;
  std::map<int, int> next_index;
  for (const auto& row : crossings) {
    const int trajectory = int(cell(row, "trajectory")), step = int(cell(row, "step"));
    CHECK(cell(row, "crossing") == next_index[trajectory]++);
    const double scale = std::hypot(cell(row, "q0"), cell(row, "q1"), std::hypot(cell(row, "p0"), cell(row, "p1")));
    CHECK(std::abs(cell(row, "q0")) <= 1e-12 * scale);
    // On the step where the sign changed: q0 < 0 before, >= 0 after; t between the two.
    const auto& before = *by_step.at({trajectory, step - 1});
    const auto& after = *by_step.at({trajectory, step});
    CHECK(cell(before, "q0") < 0.0);
    CHECK(cell(after, "q0") >= 0.0);
    CHECK(cell(row, "t") >= cell(before, "t"));
    CHECK(cell(row, "t") <= cell(after, "t"));
    // H on the numerical trajectory: as conserved as at the samples.
    CHECK(cell(row, "H") == doctest::Approx(cell(before, "H")).epsilon(1e-6));
  }
  CHECK(next_index[0] >= 3);  // t = 30: several turns
  CHECK(next_index[1] >= 3);
  const json summary = read_json(folder / "run/summary.json");
  CHECK(summary["analysis"]["poincare"]["crossings"] == next_index[0] + next_index[1]);
  const auto rows = table(folder / "run/trajectories.csv");
  CHECK(cell(rows[0], "poincare_crossings") == next_index[0]);
}

TEST_CASE("a general normal, direction both, and max_crossings stopping a trajectory as completed at that step") {
  TemporaryFolder folder;
  // The plane q0 + p1 = 0.1, both directions; two crossings each, then the trajectory stops.
  const json analysis = {
      {"poincare", {{"normal", {1.0, 0.0, 0.0, 1.0}}, {"offset", 0.1}, {"direction", "both"}, {"max_crossings", 2}}}};
  const auto result = run_named(folder, "run",
                                paper2d_job(json::array({state2(regular_q, regular_p), state2(chaotic_q, chaotic_p)}),
                                            {{"dt", 0.005}, {"steps", 5000}}, analysis));
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto crossings = table(folder / "run/poincare.csv");
  REQUIRE(crossings.size() == 4);
  const auto rows = table(folder / "run/trajectories.csv");
  for (std::size_t t = 0; t < 2; ++t) {
    CHECK(rows[t].at("status") == "completed");
    CHECK(rows[t].at("message").find("2nd Poincare crossing (max_crossings)") != std::string::npos);
    CHECK(cell(rows[t], "step") < 5000);
    double last_step = 0.0;
    for (const auto& row : crossings) {
      if (cell(row, "trajectory") != double(t)) continue;
      const double s = cell(row, "q0") + cell(row, "p1") - 0.1;
      CHECK(std::abs(s) <= 1e-12 * (std::sqrt(2.0) * 3.0 + 0.1));
      last_step = cell(row, "step");
    }
    CHECK(cell(rows[t], "step") == last_step);  // it stopped at the step of its second crossing
    // Without samples H is evaluated at step 0 and at that last state: the largest |dH/H0| includes it.
    CHECK(std::abs(cell(rows[t], "relative_energy_error")) > 0.0);
    CHECK(cell(rows[t], "max_abs_relative_energy_error") == std::abs(cell(rows[t], "relative_energy_error")));
  }
}

TEST_CASE("MEGNO: <Y> -> 2 within 5% on the regular orbit, growing on the chaotic one, FLI, OFLI, and lyapunov.csv") {
  TemporaryFolder folder;
  const json analysis = {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 10}, {"every", 10000}}},
                         {"megno", true},
                         {"fli", true},
                         {"ofli", true}};
  const auto result = run_named(folder, "run",
                                paper2d_job(json::array({state2(regular_q, regular_p), state2(chaotic_q, chaotic_p)}),
                                            {{"dt", 0.005}, {"steps", 80000}}, analysis));
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = table(folder / "run/trajectories.csv");
  MESSAGE("t = 400: regular <Y> " << rows[0].at("mean_megno") << " lambda " << rows[0].at("lyapunov0")
                                  << "; chaotic <Y> " << rows[1].at("mean_megno") << " lambda "
                                  << rows[1].at("lyapunov0"));
  CHECK(cell(rows[0], "mean_megno") == doctest::Approx(2.0).epsilon(0.05));
  CHECK(cell(rows[0], "lyapunov0") < 0.05);
  CHECK(cell(rows[1], "lyapunov0") > 0.1);
  // FLI: the supremum of ln |w| is at least ln |w(400)| = 400 lambda_1(400) (the last step is an orthonormalisation),
  // which it exceeds on the chaotic orbit by the fluctuations of the growth only; on the regular orbit |w| grows
  // like t, so FLI stays near ln t.
  MESSAGE("FLI(400): regular " << rows[0].at("fli") << ", chaotic " << rows[1].at("fli")
                               << ", ln 400 = " << std::log(400.0));
  for (const auto& row : rows) CHECK(cell(row, "fli") >= 400.0 * cell(row, "lyapunov0") - 1e-9);
  CHECK(cell(rows[1], "fli") < 400.0 * cell(rows[1], "lyapunov0") + 5.0);
  CHECK(cell(rows[0], "fli") < 2.0 * std::log(400.0));
  CHECK(cell(rows[1], "fli") > 5.0 * cell(rows[0], "fli"));
  // OFLI leaves out the growth along the flow: on the torus it stays below FLI and near ln t (the shear across the
  // flow remains); on the chaotic orbit the growth is across the flow, OFLI close to FLI.
  MESSAGE("OFLI(400): regular " << rows[0].at("ofli") << ", chaotic " << rows[1].at("ofli"));
  CHECK(cell(rows[0], "ofli") < cell(rows[0], "fli"));
  CHECK(cell(rows[0], "ofli") < 2.0 * std::log(400.0));
  CHECK(std::abs(cell(rows[1], "ofli") - cell(rows[1], "fli")) < 5.0);
  CHECK(cell(rows[1], "ofli") > 5.0 * cell(rows[0], "ofli"));
  // The series: the chaotic <Y> grows (like lambda t / 2), the regular one stays near 2.
  const auto series = table(folder / "run/lyapunov.csv");
  REQUIRE(series.size() == 16);  // 2 trajectories at steps 10000, 20000, ..., 80000
  std::vector<double> chaotic;
  for (const auto& row : series)
    if (cell(row, "trajectory") == 1.0) chaotic.push_back(cell(row, "mean_megno"));
  CHECK(chaotic.back() > 4.0 * chaotic.front());
  CHECK(chaotic.back() > 0.25 * cell(rows[1], "lyapunov0") * 400.0 / 2.0);
  CHECK(series.back().at("mean_megno") == rows[1].at("mean_megno"));  // the last row is the final estimate
  const json summary = read_json(folder / "run/summary.json");
  CHECK(summary["analysis"]["tangent_map"]["vectors"] == 1);
  CHECK(summary["analysis"]["tangent_map"]["lyapunov"]["series"] == "lyapunov.csv");
}

// Every "(....hpp)" a text of `value` names, with where it was found.
void named_headers(const json& value, const std::string& where, std::vector<std::pair<std::string, std::string>>& out) {
  if (value.is_object() || value.is_array()) {
    for (const auto& [key, item] : value.items()) named_headers(item, where + "/" + key, out);
    return;
  }
  if (!value.is_string()) return;
  static const std::regex header(R"(\(([A-Za-z0-9_/]+\.hpp)\))");
  const std::string text = value.get<std::string>();
  for (std::sregex_iterator m(text.begin(), text.end(), header), end; m != end; ++m) out.emplace_back(where, (*m)[1]);
}

TEST_CASE("the files summary.json's analysis facts name are files of the sources") {
  TemporaryFolder folder;
  const json analysis = {{"poincare", {{"component", "q1"}, {"max_crossings", 2}}},
                         {"lyapunov", {{"vectors", 2}, {"renormalize_every", 5}}},
                         {"megno", true},
                         {"sali", true}};
  const auto result =
      run_named(folder, "run", paper2d_job(state2(regular_q, regular_p), {{"dt", 0.005}, {"steps", 200}}, analysis));
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  std::vector<std::pair<std::string, std::string>> headers;
  named_headers(read_json(folder / "run/summary.json")["analysis"], "/analysis", headers);
  CHECK(headers.size() >= 4);  // the crossing locator, the tangent map, the first vector's block, SALI's factors
  const std::filesystem::path sources(NONSEP_SOURCE_DIR);
  for (const auto& header : headers) {
    const std::string& where = header.first;  // named, not bound: clang 14's CAPTURE cannot take a structured binding
    const std::string& name = header.second;
    CAPTURE(where);
    CAPTURE(name);
    // A repository path (core/include/...), or one of the host's own sources (run/..., relative to host/src).
    CHECK((std::filesystem::is_regular_file(sources / name) ||
           std::filesystem::is_regular_file(sources / "host/src" / name)));
  }
}
TEST_CASE("the host's largest exponent and states are the core's, bit for bit, with the documented first vector") {
  TemporaryFolder folder;
  const std::uint64_t steps = 3000;
  const json analysis = {{"lyapunov", {{"vectors", 2}, {"renormalize_every", 7}}}, {"megno", true}};
  const auto result =
      run_named(folder, "run", paper2d_job(state2(chaotic_q, chaotic_p), {{"dt", 0.005}, {"steps", steps}}, analysis));
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = table(folder / "run/trajectories.csv");

  volatile double opaque_dt = 0.005;
  const double dt = opaque_dt;
  const PluginPaper2D model;
  nonsep::TangentIntegrator integrator({"mpe", nonsep::ChinOptions{nonsep::Fraction(4)}});
  nonsep::PhaseSpaceBatch x = nonsep::PhaseSpaceBatch::single(chaotic_q, chaotic_p);
  // The first vector (1, 1/2, 1/3, 1/4) over (dq0, dq1, dp0, dp1); the second the unit vector of dq1.
  nonsep::PhaseSpaceBatch tangents(2, 2);
  tangents.q()[0] = 1.0, tangents.q()[1] = 0.5, tangents.p()[0] = 1.0 / 3.0, tangents.p()[1] = 0.25;
  tangents.q()[3] = 1.0;
  nonsep::LyapunovExponents exponents(2, 7);
  std::array<nonsep::LyapunovRecord, 1> record{};
  const nonsep::MegnoIndicator megno;
  std::vector<double> megno_state(nonsep::MegnoIndicator::state_numbers);
  std::array<double, 1> growth{};
  std::array<double, 2> y{};
  exponents.start(tangents, record);
  megno.start(megno_state);
  for (std::uint64_t k = 0; k < steps; ++k) {
    integrator.step(model, x, tangents, dt);
    exponents.after_step(tangents, record, dt, growth);
    megno.after_step(megno_state, growth[0], dt);
  }
  megno.values(megno_state, record[0], y);
  CHECK(cell(rows[0], "q0") == x.q()[0]);
  CHECK(cell(rows[0], "p1") == x.p()[1]);
  CHECK(cell(rows[0], "lyapunov0") == record[0].exponent(0));
  CHECK(cell(rows[0], "lyapunov1") == record[0].exponent(1));
  CHECK(cell(rows[0], "mean_megno") == y[1]);
  CHECK(cell(rows[0], "megno") == y[0]);
  CHECK(record[0].exponent(0) > 0.05);
}

TEST_CASE("tangent vectors do not change the states: trajectory.csv is the same with and without /analysis") {
  TemporaryFolder folder;
  json plain = paper2d_job(json::array({state2(regular_q, regular_p), state2(chaotic_q, chaotic_p)}),
                           {{"dt", 0.005}, {"steps", 2000}}, json::object());
  plain["output"]["every"] = 100;
  json with = plain;
  with["analysis"] = {{"lyapunov", {{"vectors", 4}}}, {"megno", true}};
  REQUIRE(run_named(folder, "plain", plain).status == 0);
  REQUIRE(run_named(folder, "with", with).status == 0);
  CHECK(read_text(folder / "plain/trajectory.csv") == read_text(folder / "with/trajectory.csv"));
  // The same drifts; the tangent stepper re-evaluates grad V where the plain step reuses its last one.
  CHECK(read_json(folder / "plain/summary.json")["evaluations"]["grad_T"] ==
        read_json(folder / "with/summary.json")["evaluations"]["grad_T"]);
}

namespace {

// 300 states (two blocks of 256) on a grid, put on the shell H = 7, with every diagnostic (three tangent vectors
// for GALI_3, two Lyapunov exponents of them); trajectories stop inside
// chunks at their max_crossings-th crossing. The basic step with t2 = -3 (cheap; accuracy does not matter here).
json ensemble_job(std::uint64_t steps, std::uint64_t max_crossings) {
  json job = paper2d_job({{"grid",
                           {{"q", {{{"from", -0.8}, {"to", 0.8}, {"count", 20}}, 0.0}},
                            {"p", {{{"from", -1.5}, {"to", 1.5}, {"count", 15}}, 0.0}}}},
                          {"energy", 7.0},
                          {"solve_for", "p1"}},
                         {{"dt", 0.002}, {"steps", steps}},
                         {{"poincare", {{"component", "q1"}, {"direction", "+"}, {"max_crossings", max_crossings}}},
                          {"lyapunov", {{"vectors", 2}, {"renormalize_every", 5}, {"every", 500}}},
                          {"megno", true},
                          {"sali", true},
                          {"gali", 3},
                          {"fli", true},
                          {"ofli", true}});
  job["output"]["every"] = 250;
  job["integrator"] = {{"scheme", "basic"}, {"t2", -3.0}};
  return job;
}

}  // namespace

TEST_CASE("--threads 1 and 2 write the same poincare.csv, lyapunov.csv and trajectories.csv, byte for byte") {
  TemporaryFolder folder;
  const json job = ensemble_job(2000, 2);
  REQUIRE(run_named(folder, "one", job, {"--threads", "1"}).status == 0);
  REQUIRE(run_named(folder, "two", job, {"--threads", "2"}).status == 0);
  for (const char* file : {"poincare.csv", "lyapunov.csv", "trajectories.csv", "trajectory.csv"}) {
    CAPTURE(file);
    CHECK(read_text(folder / "one" / file) == read_text(folder / "two" / file));
  }
  const json summary = read_json(folder / "one/summary.json");
  CHECK(summary["trajectories"].get<int>() > 256);  // two blocks at least
  CHECK(summary["energy_shell"]["left_out"].get<int>() > 0);
  CHECK(summary["energy_shell"]["left_out"].get<int>() + summary["trajectories"].get<int>() == 300);
  // Every state starts on the shell H = 7; some stopped at their second crossing, some ran to the end.
  std::map<std::string, int> statuses;
  for (const auto& row : table(folder / "one/trajectories.csv")) {
    CHECK(cell(row, "H0") == doctest::Approx(7.0).epsilon(1e-14));
    ++statuses[row.at("status") + (row.at("message").empty() ? "" : " (max_crossings)")];
  }
  CHECK(statuses["completed (max_crossings)"] > 0);
  CHECK(statuses["completed"] > 0);
}

TEST_CASE("killed and resumed: poincare.csv, lyapunov.csv and trajectories.csv bit for bit") {
  TemporaryFolder reference;
  json job = ensemble_job(60000, 25);
  job["checkpoint"] = {{"every_steps", 1000}, {"every_seconds", 0}};
  REQUIRE(run_named(reference, "out", job).status == 0);

  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", job);
  const auto step = kill_after_checkpoint(file, folder / "out", 20000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  CHECK(step < 60000);
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  for (const char* name : {"poincare.csv", "lyapunov.csv", "trajectories.csv", "trajectory.csv"}) {
    CAPTURE(name);
    CHECK(read_text(folder / "out" / name) == read_text(reference / "out" / name));
  }
  // Trajectories stopped by max_crossings both before and after the checkpoint.
  std::vector<double> stops;
  for (const auto& row : table(reference / "out/trajectories.csv"))
    if (!row.at("message").empty()) stops.push_back(cell(row, "step"));
  REQUIRE(!stops.empty());
  CHECK(*std::min_element(stops.begin(), stops.end()) < double(step));
  CHECK(*std::max_element(stops.begin(), stops.end()) > double(step));
}

TEST_CASE("Lyapunov exponents, MEGNO, SALI and GALI are refused, naming their key, for a plugin without Hessians") {
  use_test_plugins();
  TemporaryFolder folder;
  for (const char* key : {"lyapunov", "megno", "sali", "gali"}) {
    CAPTURE(key);
    json job = {{"model", {{"plugin", "blowup_gradients_only"}}},
                {"integrator", {{"scheme", "basic"}}},
                {"initial", {{"q", {0.5}}, {"p", {0.1}}}},
                {"time", {{"dt", 0.005}, {"steps", 10}}},
                {"analysis",
                 {{key, std::string(key) == "lyapunov" ? json::object()
                        : std::string(key) == "gali"   ? json(2)
                                                       : json(true)}}}};
    const auto result = run_named(folder, key, job);
    CHECK(result.status == 2);
    CHECK(result.err.find(std::string("/analysis/") + key) != std::string::npos);
    CHECK(result.err.find("no Hessians") != std::string::npos);
  }
}

TEST_CASE("an energy shell: \"p1\" takes the root p1 >= 0, \"-p1\" the root p1 <= 0, both on H = E to round-off") {
  TemporaryFolder folder;
  for (const char* solve_for : {"p1", "-p1"}) {
    CAPTURE(solve_for);
    json job = paper2d_job({{"grid", {{"q", {0.25, 0.3}}, {"p", {{{"values", {-1.5, 0.5, 3.0}}}, 99.0}}}},
                            {"energy", 7.0},
                            {"solve_for", solve_for}},
                           {{"dt", 0.005}, {"steps", 1}}, json::object());
    const auto result = run_named(folder, solve_for, job);
    INFO("stderr: " << result.err);
    REQUIRE(result.status == 0);
    const auto rows = table(folder / solve_for / "trajectories.csv");
    // p0 = 3 is off the shell: H > 7 at p1 = 0 already.
    REQUIRE(rows.size() == 2);
    CHECK(read_json(folder / solve_for / "summary.json")["energy_shell"]["left_out"] == 1);
    for (const auto& row : rows) {
      CHECK(cell(row, "H0") == doctest::Approx(7.0).epsilon(2e-16 * 4));
      CHECK(cell(row, "p1") * (std::string(solve_for) == "p1" ? 1.0 : -1.0) > 0.0);
    }
  }
}

TEST_CASE("an energy shell of a lattice of 20000 sites: O(n) through Hessian-vector products, on H = E to round-off") {
  // A dense Hessian of this size would take 3 GiB and be refused; the shell's H is one product per evaluation.
  TemporaryFolder folder;
  const std::size_t n = 20000;
  json q = json::array_t(n, json(0.0)), p = json::array_t(n, json(0.0));
  q[0] = {{"from", -0.2}, {"to", 0.2}, {"count", 3}};
  q[1] = 0.1;
  const json job = {{"model", {{"plugin", "lattice_chain"}, {"parameters", {{"sites", n}}}}},
                    {"integrator", {{"scheme", "basic"}}},
                    {"initial", {{"grid", {{"q", q}, {"p", p}}}, {"energy", 0.5}, {"solve_for", "-p0"}}},
                    {"time", {{"dt", 1e-3}, {"steps", 2}}},
                    {"output", {{"every", 0}}}};
  const auto result = run_named(folder, "lattice", job);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  CHECK(read_json(folder / "lattice" / "summary.json")["energy_shell"]["left_out"] == 0);
  const auto rows = table(folder / "lattice" / "trajectories.csv");
  REQUIRE(rows.size() == 3);
  for (const auto& row : rows) {
    CHECK(cell(row, "H0") == doctest::Approx(0.5).epsilon(1e-15));
    CHECK(cell(row, "p0") < 0.0);
  }
}

TEST_CASE("a chunk redone step by step after a divergence keeps the crossings and max_crossings stops of the others") {
  TemporaryFolder folder;
  const json analysis = {{"poincare", {{"component", "q0"}, {"max_crossings", 3}}}, {"megno", true}};
  // Alone, and in one block with a state that overflows at once: that block's chunk is redone step by step, after
  // the regular orbit already left it at its third crossing in the unchecked pass.
  const json alone =
      paper2d_job(json::array({state2(regular_q, regular_p)}), {{"dt", 0.005}, {"steps", 6000}}, analysis);
  json together = alone;
  together["initial"].push_back(state2({1e103, 0.0}, {0.0, 0.0}));
  REQUIRE(run_named(folder, "alone", alone).status == 0);
  REQUIRE(run_named(folder, "together", together).status == 1);  // diverged
  const auto rows = table(folder / "together/trajectories.csv");
  CHECK(rows[1].at("status") == "diverged");
  CHECK(rows[0].at("message").find("3rd Poincare crossing") != std::string::npos);
  CHECK(read_text(folder / "together/poincare.csv") == read_text(folder / "alone/poincare.csv"));
  const auto single = table(folder / "alone/trajectories.csv");
  for (const char* column : {"step", "q0", "q1", "p0", "p1", "mean_megno", "poincare_crossings"}) {
    CAPTURE(column);
    CHECK(rows[0].at(column) == single[0].at(column));
  }
}

TEST_CASE("a plugin failing while a crossing is located stops that trajectory as failed, and the others go on") {
  TemporaryFolder folder;
  // tests/host/plugins/blowup.cpp in 2D: H_TTV = 3 sum q_i^2 p_i^2, so each q_i p_i is conserved and
  // q_i = q_i(0) exp(6 q_i(0) p_i(0) t): q0 grows through the plane q0 = 0.5 once, q1 stays put (p1 = 0).
  // fail_single_above = 0.6 makes grad V fail in a call for one state with some |q_i| > 0.6: only the location
  // of a crossing makes such calls while both states are stepped together. The first state (q1 = 0.8) crosses
  // at t = ln(5/3)/1.8 = 0.284, and its location fails; the second (q1 = 0.1) crosses at t = ln(2.5)/0.6 = 1.53
  // and keeps |q| < 0.6 up to t_end = 1.6 (q0 = 0.52), so it is never refused, alone in its block or not.
  const json failing = {{"q", {0.3, 0.8}}, {"p", {1.0, 0.0}}}, fine = {{"q", {0.2, 0.1}}, {"p", {0.5, 0.0}}};
  json together = blowup_job(json::array({failing, fine}), {{"dimension", 2}, {"fail_single_above", 0.6}});
  together["time"] = {{"dt", 0.001}, {"steps", 1600}};
  together["analysis"] = {{"poincare", {{"component", "q0"}, {"value", 0.5}, {"direction", "+"}}}};
  json alone = together;
  alone["initial"] = json::array({fine});
  const auto result = run_named(folder, "together", together);
  INFO("stderr: " << result.err);
  CHECK(result.status == 1);  // a trajectory failed
  REQUIRE(run_named(folder, "alone", alone).status == 0);

  const auto rows = table(folder / "together/trajectories.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("status") == "failed");
  CHECK(rows[0].at("message").find("the model failed while locating a Poincare crossing in step") != std::string::npos);
  CHECK(rows[0].at("message").find("beyond fail_single_above (one state)") != std::string::npos);
  CHECK(cell(rows[0], "poincare_crossings") == 0);
  CHECK(cell(rows[0], "stop_step") == doctest::Approx(284).epsilon(0.02));  // the step of its crossing
  CHECK(rows[1].at("status") == "completed");
  CHECK(cell(rows[1], "step") == 1600);
  CHECK(cell(rows[1], "poincare_crossings") == 1);

  // The other trajectory's crossings and final state are those of a run without the failing one.
  const auto crossings = table(folder / "together/poincare.csv"), single = table(folder / "alone/poincare.csv");
  REQUIRE(crossings.size() == single.size());
  for (std::size_t i = 0; i < crossings.size(); ++i) {
    CHECK(crossings[i].at("trajectory") == "1");
    for (const char* column : {"crossing", "step", "t", "q0", "q1", "p0", "p1", "H"}) {
      CAPTURE(column);
      CHECK(crossings[i].at(column) == single[i].at(column));
    }
  }
  const auto single_rows = table(folder / "alone/trajectories.csv");
  for (const char* column : {"step", "t", "q0", "q1", "p0", "p1", "H", "poincare_crossings"}) {
    CAPTURE(column);
    CHECK(rows[1].at(column) == single_rows[0].at(column));
  }
  const json summary = read_json(folder / "together/summary.json");
  CHECK(summary["status"] == "failed");
  CHECK(summary["counts"]["failed"] == 1);
  CHECK(summary["counts"]["completed"] == 1);
}

namespace {

// The runaway warnings of a run's stderr ("nonsep: warning: trajectory N: max(|q_i|, |p_i|) grew ..."), each line.
std::vector<std::string> runaway_warnings(const std::string& err) {
  std::vector<std::string> lines;
  std::istringstream text(err);
  for (std::string line; std::getline(text, line);)
    if (line.find("runs off with bounded energy") != std::string::npos ||
        line.find("ran off the same way") != std::string::npos)
      lines.push_back(line);
  return lines;
}

// max(|q_i|, |p_i|) of a trajectory.csv row of paper2d.
double scale_of_row(const std::map<std::string, std::string>& row) {
  double scale = 0.0;
  for (const char* column : {"q0", "q1", "p0", "p1"}) scale = std::max(scale, std::abs(cell(row, column)));
  return scale;
}

// A grid of (q0, p0) on the section q1 = 0 of the shell H = 8 for couplings 0 to 0.3, Gauss 6 (stable here) and
// output.every the number of steps, as the shipped maps have it: H is evaluated at step 0 and the last step only.
json compact_shell_job(double t_end) {
  const auto steps = static_cast<std::uint64_t>(t_end / 0.02 + 0.5);
  return {
      {"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", {{"from", 0.0}, {"to", 0.3}, {"count", 4}}}}}}},
      {"integrator", {{"scheme", "gauss"}, {"stages", 3}}},
      {"initial",
       {{"grid",
         {{"q", {{{"from", -2.5}, {"to", 2.5}, {"count", 11}}, 0.0}},
          {"p", {{{"from", -2.0}, {"to", 2.0}, {"count", 9}}, 0.0}}}},
        {"energy", 8.0},
        {"solve_for", "p1"}}},
      {"time", {{"dt", 0.02}, {"t_end", t_end}}},
      {"output", {{"every", steps}}}};
}

}  // namespace

TEST_CASE("no runaway warning for paper2d's bounded orbits on the compact shell H = 8, sampled at both ends only") {
  TemporaryFolder folder;
  const auto result = run_named(folder, "run", compact_shell_job(100));
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  // What the samples alone show: orbits whose scale at the end is more than 3 times their scale at step 0, with a
  // small energy error (what the check took for a runaway when it saw only the samples); all of them on the shell,
  // whose extent |q|^2 <= (E - 2)/(2c), |p|^2 <= E - 2 (c = 1/30 at coupling 0.3: docs/dynamics.md) bounds them.
  std::map<double, double> first_scale;
  int grown = 0;
  for (const auto& row : table(folder / "run/trajectory.csv")) {
    const double trajectory = cell(row, "trajectory"), scale = scale_of_row(row);
    CHECK(scale <= std::sqrt(6.0 / (2.0 / 30.0)) + 1e-9);
    if (cell(row, "step") == 0.0)
      first_scale[trajectory] = scale;
    else if (scale > 3.0 * first_scale.at(trajectory) && std::abs(cell(row, "relative_energy_error")) <= 1e-2)
      ++grown;
  }
  MESSAGE(grown << " of " << first_scale.size() << " orbits end more than 3 times as far out as they start");
  CHECK(grown > 0);
  CHECK(runaway_warnings(result.err).empty());
}

TEST_CASE("killed after the first tenth and resumed: the runaway warnings of an uninterrupted run, none here") {
  // H evaluated every 100 steps: an uninterrupted run sees each orbit's extent in the first tenth; a resumed run
  // must know it too (from its checkpoint), not start again from the initial states.
  json job = compact_shell_job(200);
  job["output"]["energy_every"] = 100;
  job["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
  TemporaryFolder reference;
  const auto uninterrupted = run_named(reference, "out", job);
  INFO("uninterrupted stderr: " << uninterrupted.err);
  REQUIRE(uninterrupted.status == 0);

  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", job);
  const auto step = kill_after_checkpoint(file, folder / "out", 2000, folder.path());  // the first tenth: 1000
  INFO("killed after the checkpoint at step " << step);
  REQUIRE(step < 10000);
  const auto resumed =
      run_nonsep({"run", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("resumed stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  CHECK(read_text(folder / "out/trajectories.csv") == read_text(reference / "out/trajectories.csv"));
  CHECK(runaway_warnings(resumed.err) == runaway_warnings(uninterrupted.err));
  CHECK(runaway_warnings(resumed.err).empty());
}

TEST_CASE("no runaway warning for an orbit whose cyclic coordinates grow: the time and azimuth around a black hole") {
  // The shipped example's model and constants from r = 15 instead of 11 (a regular orbit, examples/given_by_h): r
  // swings between about 10 and 165 with a radial period of about 5000 (so the first tenth of a run to 60000 shows
  // that extent), while the coordinate time q0 and the azimuth q3, on which H does not depend (p0 and p3 kept to the
  // bit), grow in proportion to the proper time.
  json job = read_json(std::filesystem::path(NONSEP_SOURCE_DIR) / "examples/dynamics/schwarzschild_charged_orbit.json");
  job.erase("$schema");
  job.erase("analysis");
  job["initial"]["q"][1] = 15.0;
  job["initial"]["p"][2] = 3.4317409777285293;  // r sqrt(E^2/f - 1 - (L - beta r^2/2)^2/r^2): the mass shell
  job["time"] = {{"dt", 2.0}, {"t_end", 60000}};
  job["output"]["every"] = 15000;
  TemporaryFolder folder;
  const auto result = run_named(folder, "run", job);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = table(folder / "run/trajectory.csv");
  REQUIRE(rows.size() == 3);
  // What the check saw when it counted every coordinate: the scale grew from the time at the end of the first tenth
  // (t > tau = 6000) to ten times that.
  CHECK(cell(rows[2], "q0") > 3.0 * std::max(170.0, 1.2 * 6000));
  CHECK(cell(rows[2], "p0") == cell(rows[0], "p0"));
  CHECK(cell(rows[2], "p3") == cell(rows[0], "p3"));
  for (const auto& row : rows) CHECK(cell(row, "q1") < 200.0);
  CHECK(runaway_warnings(result.err).empty());
}

TEST_CASE("MEGNO to the scheme's order: <Y>(20) from gauss 3 stages converges at order 6 to the continuous MEGNO") {
  // paper2d at coupling 0 on q = (0.5, 0), p = (0, 2.5): deterministic to t = 20 (at coupling 0.2 one ulp of the start
  // moves <Y>(20)). The continuous Y(20) and <Y>(20) by another route: the variational equations and the MEGNO ODEs
  // dW/dt = t (w . w') / |w|^2, dZ/dt = 2 W / t, integrated by Gauss-Legendre of order 16 at h = 0.01 in 32 digits
  // (`python3 bench/indicators/reference_mp.py 0.01 8 32 0`).
  const double y_reference = 2.40073697915734, mean_y_reference = 2.00689045646938;
  TemporaryFolder folder;
  std::vector<double> y_errors, mean_errors;
  for (int steps : {2000, 4000, 8000}) {
    json job = paper2d_job(state2({0.5, 0.0}, {0.0, 2.5}), {{"dt", 20.0 / steps}, {"steps", steps}}, {{"megno", true}});
    job["model"]["parameters"] = {{"coupling", 0.0}};
    job["integrator"] = {{"scheme", "gauss"}, {"stages", 3}};
    const auto result = run_named(folder, "run" + std::to_string(steps), job);
    INFO("stderr: " << result.err);
    REQUIRE(result.status == 0);
    const auto rows = table(folder / ("run" + std::to_string(steps)) / "trajectories.csv");
    y_errors.push_back(std::abs(cell(rows[0], "megno") - y_reference));
    mean_errors.push_back(std::abs(cell(rows[0], "mean_megno") - mean_y_reference));
  }
  for (std::size_t i = 0; i < y_errors.size(); ++i)
    MESSAGE("dt = " << 0.01 / (1 << i) << ": |Y(20) - reference| " << y_errors[i] << ", |<Y>(20) - reference| "
                    << mean_errors[i]);
  for (std::size_t i = 0; i + 1 < mean_errors.size(); ++i) {
    CHECK(std::log2(mean_errors[i] / mean_errors[i + 1]) > 5.5);
    CHECK(std::log2(y_errors[i] / y_errors[i + 1]) > 5.5);
  }
  CHECK(mean_errors[1] < 1e-6);  // dt = 0.005
}

}  // namespace test_host_dynamics
