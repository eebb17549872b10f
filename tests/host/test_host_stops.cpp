// The `nonsep` executable when trajectories stop early: divergence, a plugin failing mid-run, SIGINT, and the
// stderr summary when many stop; the others continue unchanged and the outputs say what happened.
#include <doctest/doctest.h>

#include <csignal>
#include <cstdint>
#include <string>

#include "host_run_support.hpp"

namespace test_host_stops {

using nlohmann::json;
using namespace nonsep::host_testing;

TEST_CASE("a diverging trajectory stops with its step, time and variable, the others continue unchanged, exit 1") {
  TemporaryFolder folder;
  // grad V = q^3 overflows for |q| > 5.6e102: the middle state turns non-finite in its first step.
  const json list = json::array({state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)});
  const json summary = run_job(folder, "diverging", blowup_job(list), 1);
  CHECK(summary["status"] == "diverged");
  const json& diverged = summary["trajectories"][1];
  CHECK(diverged["status"] == "diverged");
  CHECK(diverged["stop"]["step"] == 1);
  CHECK(number(diverged["stop"]["t"]) == 0.001);
  const std::string variable = diverged["stop"]["variable"];
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
  const json summary = read_run(folder / "failing.out");
  CHECK(summary["status"] == "failed");
  CHECK(summary["trajectories"][1]["status"] == "failed");
  CHECK(summary["trajectories"][1]["message"].get<std::string>().find("beyond fail_above") != std::string::npos);
  CHECK(summary["trajectories"][0]["status"] == "completed");
  CHECK(summary["trajectories"][2]["status"] == "completed");
  const json survivors = run_job(folder, "survivors", blowup_job(json::array({state(1.0, 0.5), state(-0.5, 0.25)})));
  CHECK(summary["trajectories"][0]["final"] == survivors["trajectories"][0]["final"]);
  CHECK(summary["trajectories"][2]["final"] == survivors["trajectories"][1]["final"]);
}

TEST_CASE("SIGINT: the run finishes its step, writes its outputs with status interrupted and exits 130") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["time"] = {{"dt", 1e-6}, {"steps", 1000000000000}};
  job["output"] = {{"directory", "out"}, {"every", 1000}};
  const auto file = write_job(folder / "long.json", job);
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  const auto csv = folder / "out" / "trajectory.csv";
  REQUIRE(wait_until([&] { return std::filesystem::exists(csv) && read_text(csv).size() > 2000; }));
  REQUIRE(::kill(process.pid, SIGINT) == 0);
  const auto result = finish(process, std::chrono::seconds(30));
  INFO("stderr: " << result.err);
  CHECK(result.status == 130);
  const json summary = read_run(folder / "out");
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

TEST_CASE("many trajectories stop: stderr names the first 20 and says how many more trajectories.csv lists") {
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
  CHECK(result.err.find("... and 5 more trajectories that stopped early; ") != std::string::npos);
  CHECK(read_json(folder / "many.out/summary.json")["counts"]["diverged"] == 25);
}

}  // namespace test_host_stops
