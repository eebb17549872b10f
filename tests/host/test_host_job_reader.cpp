// The job reader in-process: values, defaults from the scheme catalogue, the time grid, initial-state shapes, and
// that every problem is reported with its JSON path, all at once.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/strict_json.hpp"
#include "nonsep/host/platform/build_features.hpp"

namespace test_host_job_reader {

using nlohmann::json;
using namespace nonsep;
using namespace nonsep::host;

namespace {

struct Parsed {
  Job job;
  std::vector<JobIssue> issues;
};

Parsed parse(const json& document, const std::string& file = "/jobs/test.json") {
  Parsed parsed;
  parsed.job = parse_job(document, file, parsed.issues);
  return parsed;
}

Parsed parse_text(const std::string& text) {
  Parsed parsed;
  if (auto document = parse_job_text(text, parsed.issues))
    parsed.job = parse_job(*document, "/jobs/test.json", parsed.issues);
  return parsed;
}

std::vector<std::string> paths(const std::vector<JobIssue>& issues) {
  std::vector<std::string> result;
  for (const auto& issue : issues) result.push_back(issue.path);
  return result;
}

bool names(const std::vector<JobIssue>& issues, const std::string& path) {
  return std::any_of(issues.begin(), issues.end(), [&](const JobIssue& issue) { return issue.path == path; });
}

json with_time(json time) {
  json job = host_testing::quickstart_job();
  job["time"] = std::move(time);
  return job;
}

}  // namespace

TEST_CASE("the quickstart job reads into the values it spells out") {
  const auto parsed = parse(host_testing::quickstart_job());
  REQUIRE(parsed.issues.empty());
  const Job& job = parsed.job;
  CHECK(job.plugin == "paper1d");
  CHECK(job.parameters == json::object());
  CHECK(job.run().integrator.scheme == "triplet");
  CHECK(std::get<ChinOptions>(job.run().integrator.options).order == Fraction(4, 3));
  CHECK(std::get<ChinOptions>(job.run().integrator.options).t2 == -2.0);
  CHECK(job.run().integrator.form == HamiltonianForm::TTV);
  CHECK(job.initial.shape == "single");
  CHECK(job.initial.count == 1);
  CHECK(job.initial.q == std::vector<double>{2.0});
  CHECK(job.initial.p == std::vector<double>{0.0});
  CHECK(job.output_directory == std::filesystem::path("/jobs/quickstart.out"));
  CHECK(job.run().every == 1);
}

TEST_CASE("integrator options left out take the catalogue's defaults") {
  for (const auto& scheme : scheme_catalogue()) {
    CAPTURE(scheme.name);
    json document = host_testing::quickstart_job();
    document["integrator"] = {{"scheme", scheme.name}};
    const auto parsed = parse(document);
    REQUIRE(parsed.issues.empty());
    for (const auto& parameter : scheme.parameters) {
      REQUIRE_FALSE(parameter.default_text.empty());
      CHECK(option_value(parsed.job.run().integrator, parameter) == default_option_value(parameter));
    }
  }
  CHECK(std::get<ChinOptions>(parse(host_testing::quickstart_job()).job.run().integrator.options).t2 !=
        ChinCoefficients::default_t2());
}

TEST_CASE("orders are exact fractions or integers and must exist for the scheme") {
  json document = host_testing::quickstart_job();
  document["integrator"] = {{"scheme", "triplet"}, {"order", 2}};
  CHECK(std::get<ChinOptions>(parse(document).job.run().integrator.options).order == Fraction(2));
  document["integrator"]["order"] = " 8 / 3 ";
  CHECK(std::get<ChinOptions>(parse(document).job.run().integrator.options).order == Fraction(8, 3));
  document["integrator"]["order"] = 2.0;
  CHECK(std::get<ChinOptions>(parse(document).job.run().integrator.options).order == Fraction(2));
  for (const json& bad : {json("5/3"), json(1.5), json("4/3x"), json(0), json("-4/3"), json(true)}) {
    CAPTURE(bad.dump());
    document["integrator"]["order"] = bad;
    CHECK(paths(parse(document).issues) == std::vector<std::string>{"/integrator/order"});
  }
  document["integrator"] = {{"scheme", "basic"}, {"order", "4/3"}};
  const auto issues = parse(document).issues;
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/integrator/order");
  CHECK(issues[0].allowed.find("2/3") != std::string::npos);
  CHECK(issues[0].allowed == "the highest order of basic is 2/3");  // the value said once, by "found"
}

TEST_CASE("t_end is reached exactly: steps = ceil(t_end/dt) with a relative slack of 1e-9, dt = t_end/steps") {
  struct Case {
    double dt, t_end;
    std::uint64_t steps;
  };
  for (const Case c : {Case{0.005, 0.3863765573361232, 78}, Case{0.1, 0.3, 3}, Case{0.1, 0.7, 7}, Case{0.1, 1.0, 10},
                       Case{0.1, 1.01, 11}, Case{0.1, 1.0000000001, 10}, Case{1.0, 0.25, 1}, Case{-0.01, -0.05, 5}}) {
    CAPTURE(c.dt);
    CAPTURE(c.t_end);
    const auto parsed = parse(with_time({{"dt", c.dt}, {"t_end", c.t_end}}));
    REQUIRE(parsed.issues.empty());
    const TimeGrid& time = parsed.job.run().time;
    CHECK(time.steps == c.steps);
    CHECK(time.dt == c.t_end / static_cast<double>(c.steps));
    CHECK(time.dt_requested == c.dt);
    CHECK(time.t_end == c.t_end);
    CHECK(time.time_at(time.steps) == c.t_end);
    CHECK(std::abs(time.dt) <= std::abs(c.dt) * (1.0 + 1e-9));
  }
}

TEST_CASE("steps instead of t_end: exactly that many steps of dt") {
  const auto parsed = parse(with_time({{"dt", 0.25}, {"steps", 12}}));
  REQUIRE(parsed.issues.empty());
  CHECK(parsed.job.run().time.steps == 12);
  CHECK(parsed.job.run().time.dt == 0.25);
  CHECK(parsed.job.run().time.t_end == 3.0);
  CHECK(parsed.job.run().time.time_at(5) == 1.25);
  CHECK_FALSE(parsed.job.run().time.from_t_end);
}

TEST_CASE("a time grid subdivided into m: m times the steps, of dt / m, ending where it ends") {
  for (const json& time : {json{{"dt", 0.005}, {"t_end", 0.3863765573361232}}, json{{"dt", 0.1}, {"steps", 7}}}) {
    CAPTURE(time);
    const auto parsed = parse(with_time(time));
    REQUIRE(parsed.issues.empty());
    const TimeGrid& grid = parsed.job.run().time;
    for (const std::uint64_t m : {1, 2, 3}) {
      CAPTURE(m);
      const TimeGrid fine = grid.subdivided(m);
      CHECK(fine.steps == grid.steps * m);
      CHECK(fine.from_t_end == grid.from_t_end);
      CHECK(fine.dt_requested == grid.dt_requested / static_cast<double>(m));
      // Read as the job reader reads a job with that step, wherever the grid came from.
      const TimeGrid read = grid.from_t_end ? TimeGrid::to_end(grid.t_end, fine.dt_requested, fine.steps)
                                            : TimeGrid::of_steps(fine.steps, fine.dt_requested);
      CHECK(fine.dt == read.dt);
      CHECK(fine.t_end == read.t_end);
      if (grid.from_t_end) CHECK(fine.t_end == grid.t_end);
    }
  }
}

TEST_CASE("time: the problems of dt, t_end and steps") {
  CHECK(paths(parse(with_time({{"dt", 0.01}, {"t_end", -1.0}})).issues) == std::vector<std::string>{"/time/t_end"});
  CHECK(paths(parse(with_time({{"dt", 0.0}, {"steps", 3}})).issues) == std::vector<std::string>{"/time/dt"});
  CHECK(paths(parse(with_time({{"dt", 0.1}})).issues) == std::vector<std::string>{"/time/t_end"});
  CHECK(paths(parse(with_time({{"dt", 0.1}, {"steps", 2}, {"t_end", 0.2}})).issues) ==
        std::vector<std::string>{"/time/steps"});
  CHECK(paths(parse(with_time({{"dt", 0.1}, {"steps", 0}})).issues) == std::vector<std::string>{"/time/steps"});
  CHECK(paths(parse(with_time({{"dt", 1e300}, {"steps", 1000000000}})).issues) ==
        std::vector<std::string>{"/time/steps"});
  CHECK(paths(parse(with_time({{"dt", 1e-12}, {"t_end", 1e6}})).issues) == std::vector<std::string>{"/time/t_end"});
  CHECK(paths(parse(with_time({{"dt", 0.1}, {"steps", 4}, {"stop", 1}})).issues) ==
        std::vector<std::string>{"/time/stop"});
}

TEST_CASE("an end time whose t_end / dt overflows a double is over the step limit, for a run and a study") {
  for (const auto& [dt, t_end] : {std::pair{1e-308, 1e308}, std::pair{5e-324, 1.0}, std::pair{-5e-324, -1.0}}) {
    const double step = dt;  // clang 14 cannot capture a structured binding
    CAPTURE(step);
    const auto issues = parse(with_time({{"dt", dt}, {"t_end", t_end}})).issues;
    REQUIRE(paths(issues) == std::vector<std::string>{"/time/t_end"});
    CHECK(issues[0].found.find("beyond the largest double") != std::string::npos);
    CHECK(issues[0].allowed == "at most " + std::to_string(max_steps) + " steps");
  }
  json study = host_testing::quickstart_job();
  study.erase("integrator");
  study.erase("output");
  study["time"] = {{"t_end", 1.0}};
  study["study"] = {{"dt", {0.1, 5e-324}}, {"integrators", {{{"scheme", "basic"}}}}};
  const auto issues = parse(study).issues;
  REQUIRE(paths(issues) == std::vector<std::string>{"/study/dt/1"});
  CHECK(issues[0].allowed == "at most " + std::to_string(max_steps) + " steps");
}

TEST_CASE("initial states: one, a list, or a grid in row-major order (last axis fastest)") {
  json document = host_testing::quickstart_job();
  document["initial"] = json::array({{{"q", {1.0}}, {"p", {0.5}}}, {{"q", {2.0}}, {"p", {-0.5}}}});
  auto parsed = parse(document);
  REQUIRE(parsed.issues.empty());
  CHECK(parsed.job.initial.shape == "list");
  CHECK(parsed.job.initial.q == std::vector<double>{1.0, 2.0});
  CHECK(parsed.job.initial.p == std::vector<double>{0.5, -0.5});

  document["initial"] = {
      {"grid", {{"q", {{{"from", 0.0}, {"to", 1.0}, {"count", 3}}, 7.0}}, {"p", {{{"values", {5.0, 6.0}}}, -1.0}}}}};
  parsed = parse(document);
  REQUIRE(parsed.issues.empty());
  const InitialStates& states = parsed.job.initial;
  CHECK(states.shape == "grid");
  CHECK(states.dimension == 2);
  REQUIRE(states.count == 6);
  // q0 in {0, 0.5, 1} (slowest), q1 = 7, p0 in {5, 6}, p1 = -1.
  CHECK(states.q == std::vector<double>{0.0, 7.0, 0.0, 7.0, 0.5, 7.0, 0.5, 7.0, 1.0, 7.0, 1.0, 7.0});
  CHECK(states.p == std::vector<double>{5.0, -1.0, 6.0, -1.0, 5.0, -1.0, 6.0, -1.0, 5.0, -1.0, 6.0, -1.0});

  document["initial"] = {{"grid",
                          {{"q", {{{"from", 0.0}, {"to", 1.0}, {"count", 1000}}}},
                           {"p", {{{"from", 0.0}, {"to", 1.0}, {"count", 1001}}}}}}};
  CHECK(paths(parse(document).issues) == std::vector<std::string>{"/initial/grid"});

  // Found by fuzzing: axes are refused as soon as their product is too large, before the rest are allocated
  // (here 200 axes of a million values each would need 1.6 GB), and a grid of allowed size but large dimension
  // must not ask for more than max_initial_values numbers.
  json huge_axes = json::array();
  for (int i = 0; i < 200; ++i) huge_axes.push_back({{"from", 0.0}, {"to", 1.0}, {"count", 1000000}});
  document["initial"] = {{"grid", {{"q", huge_axes}, {"p", huge_axes}}}};
  CHECK(paths(parse(document).issues) == std::vector<std::string>{"/initial/grid"});
  json wide_q = json::array({{{"from", 0.0}, {"to", 1.0}, {"count", 1000000}}}), wide_p = json::array({0.0});
  for (int i = 0; i < 150; ++i) {
    wide_q.push_back(0.0);
    wide_p.push_back(0.0);
  }
  document["initial"] = {{"grid", {{"q", wide_q}, {"p", wide_p}}}};
  const auto wide = parse(document);
  REQUIRE(paths(wide.issues) == std::vector<std::string>{"/initial/grid"});
  CHECK(wide.issues[0].found == "a grid of 1000000 states of dimension 151");
}

TEST_CASE("a range {from, to, count}: its ends exactly, count 1 is `from`, every value finite and between the ends") {
  const auto axis = [](double from, double to, int count) {
    json document = host_testing::quickstart_job();
    document["initial"] = {{"grid", {{"q", {{{"from", from}, {"to", to}, {"count", count}}}}, {"p", {0.0}}}}};
    const auto parsed = parse(document);
    REQUIRE(parsed.issues.empty());
    return parsed.job.initial.q;
  };
  CHECK(axis(2.0, 3.0, 1) == std::vector<double>{2.0});
  CHECK(axis(2.0, 3.0, 2) == std::vector<double>{2.0, 3.0});
  // The ends exactly and the values between them the doubles nearest the decimal ones: 0 to 0.3 in 16 values has
  // 0.06 (not 0.05999999999999999) and 0.3 itself, which a parameter of maximum 0.3 accepts; 0 to 0.4 in 9 values has
  // 0.3 (not 0.30000000000000004).
  const std::vector<double> fine = axis(0.0, 0.3, 16);
  REQUIRE(fine.size() == 16);
  CHECK(fine[3] == 0.06);
  CHECK(fine[15] == 0.3);
  CHECK(axis(0.0, 0.4, 9)[6] == 0.3);
  CHECK(axis(0.1, 0.7, 7) == std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7});
  CHECK(axis(-1.0, 1.0, 3)[1] == 0.0);
  CHECK(axis(1e-30, 1e10, 5)[2] == 5e9);
  // Ends near the largest double: (to - from) overflows, yet every value is finite and between the ends.
  CHECK(axis(-1e308, 1e308, 3) == std::vector<double>{-1e308, 0.0, 1e308});
  const std::vector<double> wide = axis(-1e308, 1e308, 4);
  REQUIRE(wide.size() == 4);
  CHECK(wide.front() == -1e308);
  CHECK(wide.back() == 1e308);
  CHECK(std::is_sorted(wide.begin(), wide.end()));
  CHECK(std::all_of(wide.begin(), wide.end(), [](double x) { return std::isfinite(x); }));
  CHECK(axis(1.7e308, 1.75e308, 3)[1] == doctest::Approx(1.725e308));

  // A swept parameter's range alike: count 1 is the value `from`.
  json document = host_testing::quickstart_job();
  document["model"]["parameters"] = {{"coupling", {{"from", 0.2}, {"to", 0.3}, {"count", 1}}}};
  const auto parsed = parse(document);
  REQUIRE(parsed.issues.empty());
  REQUIRE(parsed.job.sweep.size() == 1);
  CHECK(parsed.job.sweep[0].values == std::vector<json>{0.2});
}

TEST_CASE("checkpoint: every_steps and every_seconds, with defaults, and each problem with its path") {
  json document = host_testing::quickstart_job();
  auto parsed = parse(document);
  CHECK(parsed.job.run().checkpoint.every_steps == 0);
  CHECK(parsed.job.run().checkpoint.every_seconds == 60.0);
  document["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
  parsed = parse(document);
  CHECK(parsed.issues.empty());
  CHECK(parsed.job.run().checkpoint.every_steps == 500);
  CHECK(parsed.job.run().checkpoint.every_seconds == 0.0);
  document["checkpoint"] = {{"every_steps", 2.5}, {"every_seconds", -1}, {"every_minute", 1}};
  CHECK(paths(parse(document).issues) ==
        std::vector<std::string>{"/checkpoint/every_minute", "/checkpoint/every_steps", "/checkpoint/every_seconds"});
  // 2^63 as a double is integral but beyond std::int64_t: refused, not converted (undefined behaviour).
  document["checkpoint"] = {{"every_steps", 9.223372036854775807e18}};
  CHECK(paths(parse(document).issues) == std::vector<std::string>{"/checkpoint/every_steps"});
  document.erase("checkpoint");
  document["output"]["every"] = 9.223372036854775807e18;
  CHECK(paths(parse(document).issues) == std::vector<std::string>{"/output/every"});
}

TEST_CASE("analysis: closest_return_after is a finite time, max_relative_energy_error a finite positive bound") {
  json document = host_testing::quickstart_job();
  auto parsed = parse(document);
  CHECK_FALSE(parsed.job.run().analysis.closest_return_after);
  CHECK_FALSE(parsed.job.run().analysis.max_relative_energy_error);
  document["analysis"] = {{"closest_return_after", -1.5}, {"max_relative_energy_error", 1e-6}};
  parsed = parse(document);
  REQUIRE(parsed.issues.empty());
  CHECK(parsed.job.run().analysis.closest_return_after == -1.5);
  CHECK(parsed.job.run().analysis.max_relative_energy_error == 1e-6);
  for (const json& bad :
       {json(0), json(-1e-3), json("1e-6"), json(nullptr), json(std::numeric_limits<double>::infinity())}) {
    CAPTURE(bad.dump());
    document["analysis"] = {{"max_relative_energy_error", bad}};
    parsed = parse(document);
    REQUIRE(paths(parsed.issues) == std::vector<std::string>{"/analysis/max_relative_energy_error"});
    CHECK(parsed.issues[0].allowed.rfind("a finite number > 0", 0) == 0);
  }
}

TEST_CASE("every problem of a job is reported at once, each with its JSON path") {
  json document = host_testing::quickstart_job();
  document["colour"] = "blue";
  document["model"]["plugin"] = "";
  document["hamiltonian"] = "TVT";
  document["integrator"]["order"] = "4/3x";
  document["integrator"]["t2"] = 0.0;
  document["initial"] = json::array({{{"q", {1.0}}, {"p", {0.0}}}, {{"q", {"x"}}, {"p", {0.0}}}, {{"q", {1.0}}}});
  document["time"]["dt"] = -0.0;
  document["output"]["every"] = -3;
  const auto parsed = parse(document);
  for (const char* path : {"/colour", "/model/plugin", "/hamiltonian", "/integrator/order", "/integrator/t2",
                           "/initial/1/q/0", "/initial/2/p", "/time/dt", "/output/every"}) {
    CAPTURE(path);
    CHECK(names(parsed.issues, path));
  }
  CHECK(parsed.issues.size() == 9);
  for (const auto& issue : parsed.issues) {
    CHECK_FALSE(issue.found.empty());
    CHECK_FALSE(issue.allowed.empty());
  }
}

TEST_CASE("a scheme option the core refuses: the rule beside the value as the job has it, the value said once") {
  json document = host_testing::quickstart_job();
  const auto issue_of = [&](const json& integrator) {
    document["integrator"] = integrator;
    const auto parsed = parse(document);
    REQUIRE(parsed.issues.size() == 1);
    return parsed.issues[0];
  };
  const auto stages = issue_of({{"scheme", "gauss"}, {"stages", 9}});
  CHECK(stages.path == "/integrator/stages");
  CHECK(stages.found == "9");
  CHECK(stages.allowed == "Gauss-Legendre collocation has 1 to 8 stages, orders 2 to 16");
  const auto whole = issue_of({{"scheme", "gauss"}, {"stages", 2.5}});
  CHECK(whole.found == "2.5");
  CHECK(whole.allowed == "stages must be a whole number");
  const auto t2 = issue_of({{"scheme", "basic"}, {"t2", 0.0}});
  CHECK(t2.allowed == "t2 must be a finite non-zero number; the default is -6^(1/3) = -1.8171205928321397");
  const auto omega = issue_of({{"scheme", "tao"}, {"order", 2}, {"omega", -1.0}});
  CHECK(omega.allowed == "the binding omega must be finite and positive; the default is 20");
}

TEST_CASE("an unknown scheme still gets its options checked") {
  json document = host_testing::quickstart_job();
  document["integrator"] = {{"scheme", "rk4"}, {"order", "x"}, {"step", 2}};
  CHECK(paths(parse(document).issues) ==
        std::vector<std::string>{"/integrator/step", "/integrator/scheme", "/integrator/order"});
}

TEST_CASE("strict JSON: syntax errors give line and column, duplicate keys are refused with their path") {
  auto parsed = parse_text("{\n  \"model\": {\"plugin\": \"paper1d\"},\n  \"time\": { \"dt\": 0.1 \"steps\": 1 }\n}");
  REQUIRE(parsed.issues.size() == 1);
  CHECK(parsed.issues[0].path.empty());
  CHECK(parsed.issues[0].found.find("line 3") != std::string::npos);

  parsed = parse_text(R"({"initial": [{"q": [1], "p": [0]}, {"q": [1], "q": [2], "p": [0]}]})");
  CHECK(paths(parsed.issues) == std::vector<std::string>{"/initial/1/q"});

  parsed = parse_text(R"({"model": {"parameters": {"a/b": 1, "a/b": 2}}})");
  CHECK(paths(parsed.issues) == std::vector<std::string>{"/model/parameters/a~1b"});
}

TEST_CASE("initial states must have the model's dimension") {
  InitialStates states;
  states.shape = "list";
  states.dimension = 2;
  states.count = 3;
  std::vector<JobIssue> issues;
  check_dimension(states, 2, issues);
  CHECK(issues.empty());
  check_dimension(states, 1, issues);
  CHECK(paths(issues) == std::vector<std::string>{"/initial/0/q"});
  states.shape = "grid";
  check_dimension(states, 3, issues);
  CHECK(issues.back().path == "/initial/grid/q");
}

TEST_CASE("the output folder is relative to the job file, by default <job>.out beside it") {
  json document = host_testing::quickstart_job();
  document.erase("output");
  auto parsed = parse(document, "/data/runs/orbit.json");
  CHECK(parsed.job.output_directory == std::filesystem::path("/data/runs/orbit.out"));
  CHECK(parsed.job.run().every == 1);
  document["output"] = {{"directory", "results/a"}, {"every", 0}};
  parsed = parse(document, "/data/runs/orbit.json");
  CHECK(parsed.job.output_directory == std::filesystem::path("/data/runs/results/a"));
  CHECK(parsed.job.run().every == 0);
  document["output"] = {{"directory", "/abs/out"}};
  CHECK(parse(document, "/data/runs/orbit.json").job.output_directory == std::filesystem::path("/abs/out"));
}

TEST_CASE("load_job reports a missing file and a plugin that cannot be loaded as issues") {
  host_testing::TemporaryFolder folder;
  try {
    load_job(folder / "absent.json");
    FAIL("no exception");
  } catch (const InvalidJob& error) {
    REQUIRE(error.issues().size() == 1);
    CHECK(error.issues()[0].path.empty());
  }
  json document = host_testing::quickstart_job();
  document["model"]["plugin"] = "./nowhere/model.so";
  document["time"]["dt"] = 0;
  const auto file = host_testing::write_job(folder / "job.json", document);
  try {
    load_job(file);
    FAIL("no exception");
  } catch (const InvalidJob& error) {
    CHECK(paths(error.issues()) == std::vector<std::string>{"/time/dt", "/model/plugin"});
    CHECK(std::string(error.what()).find("2 problems") != std::string::npos);
  }
}

TEST_CASE("/output/format \"hdf5\": accepted by a build with HDF5, refused at /output/format by one without") {
  json document = nonsep::host_testing::quickstart_job();
  document["output"]["format"] = "hdf5";
  const Parsed parsed = parse(document);
  if (built_with_hdf5()) {
    CHECK(parsed.issues.empty());
    CHECK(parsed.job.run().format == OutputFormat::hdf5);
  } else {
    REQUIRE(parsed.issues.size() == 1);
    CHECK(parsed.issues[0].path == "/output/format");
    CHECK(parsed.issues[0].found.find("this build of nonsep has no HDF5") != std::string::npos);
  }
}

}  // namespace test_host_job_reader
