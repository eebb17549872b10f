// Models given by H(q, p) itself (plugin ABI version 6) through the executable: Chin's schemes refused before
// anything runs, with the schemes that apply named; a dimension mismatch and the VVT form refused; gauss with
// Lyapunov exponents and the energy from H; scheme auto choosing among the schemes that apply.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "host_run_support.hpp"

namespace test_host_general_hamiltonian {

using json = nlohmann::json;
using namespace nonsep::host_testing;

namespace {

json henon_heiles_job(json integrator) {
  return {{"model", {{"plugin", "henon_heiles"}}},
          {"integrator", std::move(integrator)},
          {"initial", {{"q", {0.0, 0.1}}, {"p", {0.49, 0.0}}}},
          {"time", {{"dt", 0.01}, {"steps", 100}}},
          {"output", {{"every", 10}}}};
}

Result run_and_validate(const TemporaryFolder& folder, const std::string& name, const json& job,
                        const std::string& command) {
  const auto file = write_job(folder / (name + ".json"), job);
  if (command == "validate") return run_nonsep({"validate", file.string()}, folder.path());
  return run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path());
}

}  // namespace

TEST_CASE("a model given by H: Chin's schemes refused before anything runs, naming the schemes that apply") {
  TemporaryFolder folder;
  for (const char* command : {"run", "validate"})
    for (const json& integrator : {json{{"scheme", "basic"}}, json{{"scheme", "triplet"}, {"order", "4/3"}},
                                   json{{"scheme", "mpe"}, {"order", 4}}}) {
      const std::string scheme = integrator["scheme"];
      CAPTURE(scheme);
      CAPTURE(std::string(command));
      const Result result = run_and_validate(folder, scheme, henon_heiles_job(integrator), command);
      CHECK(result.status == 2);
      CHECK(result.err.find("/integrator/scheme") != std::string::npos);
      CHECK(result.err.find("\"" + scheme + "\" with the plugin 'henon_heiles', a model given by H(q, p) itself") !=
            std::string::npos);
      CHECK(result.err.find("need H in product form") != std::string::npos);
      CHECK(result.err.find("a scheme that integrates H itself: tao, implicit_midpoint, gauss") != std::string::npos);
      CHECK_FALSE(std::filesystem::exists(folder / scheme / "summary.json"));
    }
}

TEST_CASE("a model given by H: a dimension mismatch and the VVT form refused with exit status 2") {
  TemporaryFolder folder;
  json job = henon_heiles_job({{"scheme", "gauss"}, {"stages", 3}});
  job["initial"] = {{"q", {0.1}}, {"p", {0.2}}};
  const Result mismatch = run_and_validate(folder, "mismatch", job, "run");
  CHECK(mismatch.status == 2);
  CHECK(mismatch.err.find("/initial") != std::string::npos);
  CHECK(mismatch.err.find("dimension") != std::string::npos);
  json vvt = henon_heiles_job({{"scheme", "gauss"}, {"stages", 3}});
  vvt["hamiltonian"] = "VVT";
  const Result form = run_and_validate(folder, "vvt", vvt, "validate");
  CHECK(form.status == 2);
  CHECK(form.err.find("/hamiltonian") != std::string::npos);
  CHECK(form.err.find("which has no T and V to exchange") != std::string::npos);
}

TEST_CASE("a model given by H: gauss with Lyapunov exponents and MEGNO, the energy from H, tao and the midpoint") {
  TemporaryFolder folder;
  json job = henon_heiles_job({{"scheme", "gauss"}, {"stages", 3}});
  job["initial"] = json::array({{{"q", {0.0, 0.1}}, {"p", {0.49, 0.0}}}, {{"q", {0.0, -0.2}}, {"p", {0.4, 0.2}}}});
  job["time"] = {{"dt", 0.01}, {"steps", 2000}};
  job["analysis"] = {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 10}}}, {"megno", true}};
  const json summary = run_job(folder, "gauss", job);
  CHECK(summary["status"] == "completed");
  CHECK(summary["hamiltonian"] == "general");
  CHECK(summary["evaluations"]["grad_T"] == 0);
  CHECK(summary["evaluations"]["grad_H"].get<std::uint64_t>() > 2 * 3 * 2000);
  CHECK(summary["energy"]["available"] == true);
  CHECK(number(summary["energy"]["largest_relative_error"]["value"]) < 1e-12);
  CHECK(summary["trajectories"].size() == 2);
  for (const json& integrator : {json{{"scheme", "tao"}, {"order", 4}}, json{{"scheme", "implicit_midpoint"}}}) {
    const std::string scheme = integrator["scheme"];
    const json other = run_job(folder, scheme, henon_heiles_job(integrator));
    CHECK(other["status"] == "completed");
  }
}

TEST_CASE("a model given by H: scheme auto chooses among the schemes that integrate H") {
  TemporaryFolder folder;
  json job = henon_heiles_job({{"scheme", "auto"}, {"tolerance", 1e-8}});
  job["time"] = {{"dt", 0.1}, {"steps", 100}};
  const json summary = run_job(folder, "auto", job);
  const json& choice = summary["scheme_choice"];
  CHECK(choice["candidates"].size() == 4);  // gauss 16, 8, 6 and 4
  CHECK(choice["chosen"].get<std::string>().rfind("gauss", 0) == 0);
  CHECK(summary["integrator"]["scheme"] == "gauss");
}

TEST_CASE("a model given by H: initial states on an energy shell, solved for p1 through value_H") {
  // Henon-Heiles, H = (px^2 + py^2)/2 + (x^2 + y^2)/2 + x^2 y - y^3/3, on the shell H = 1/8 from the line x = 0,
  // px = 0, y from -0.3 to 0.3: every state's H is the shell's to round-off.
  TemporaryFolder folder;
  json job = henon_heiles_job({{"scheme", "gauss"}, {"stages", 3}});
  const json y_axis = {{"from", -0.3}, {"to", 0.3}, {"count", 5}};
  json grid = json::object();
  grid["q"] = json::array({0.0, y_axis});
  grid["p"] = json::array({0.0, 0.0});
  job["initial"] = json::object();
  job["initial"]["grid"] = grid;
  job["initial"]["energy"] = 0.125;
  job["initial"]["solve_for"] = "p1";
  job["time"] = {{"dt", 0.01}, {"steps", 10}};
  const json summary = run_job(folder, "shell", job);
  CHECK(summary["status"] == "completed");
  REQUIRE(summary["trajectories"].size() == 5);
  for (const json& trajectory : summary["trajectories"])
    CHECK(std::abs(trajectory["energy"]["initial"].get<double>() - 0.125) < 1e-15);
}

TEST_CASE("a model given by H: killed and resumed bit for bit, with threads, a sweep, MEGNO, OFLI and results.h5") {
  // A magnetic bottle swept over its mirror, gauss 3 stages with MEGNO, OFLI (grad H of each set's model at time 0
  // and every step) and a Lyapunov exponent: the files of one
  // thread, of two, and of a run killed after a checkpoint and resumed are the same bytes; HDF5 output completes.
  const json job = {
      {"model", {{"plugin", "magnetic_bottle"}, {"parameters", {{"omega", 0.2}, {"mirror", json::array({0.3, 0.6})}}}}},
      {"integrator", {{"scheme", "gauss"}, {"stages", 3}}},
      {"initial",
       {{"grid",
         {{"q", {{{"from", 0.5}, {"to", 1.5}, {"count", 2}}, 0.0, 0.0}},
          {"p", {0.0, {{"from", -0.5}, {"to", 0.5}, {"count", 2}}, 0.5}}}}}},
      {"time", {{"dt", 0.02}, {"steps", 20000}}},
      {"output", {{"every", 5000}}},
      {"analysis",
       {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 10}, {"every", 1000}}}, {"megno", true}, {"ofli", true}}},
      {"checkpoint", {{"every_steps", 1000}, {"every_seconds", 0}}}};
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", job);
  const auto one = run_nonsep(
      {"run", "--quiet", "--threads", "1", "--output", (folder / "one").string(), file.string()}, folder.path());
  INFO("stderr: " << one.err);
  REQUIRE(one.status == 0);
  const auto two = run_nonsep(
      {"run", "--quiet", "--threads", "2", "--output", (folder / "two").string(), file.string()}, folder.path());
  REQUIRE(two.status == 0);
  const std::uint64_t step = kill_after_checkpoint(file, folder / "killed", 2000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  REQUIRE(step < 20000);
  const auto resumed = run_nonsep(
      {"run", "--quiet", "--resume", "--output", (folder / "killed").string(), file.string()}, folder.path());
  INFO("resumed stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  for (const char* name : {"trajectory.csv", "trajectories.csv", "lyapunov.csv"}) {
    CAPTURE(name);
    const std::string reference = read_text(folder / "one" / name);
    CHECK(!reference.empty());
    CHECK(read_text(folder / "two" / name) == reference);
    CHECK(read_text(folder / "killed" / name) == reference);
  }
  const json summary = read_json(folder / "one" / "summary.json");
  CHECK(summary["hamiltonian"] == "general");
  CHECK(summary["counts"]["completed"] == 8);
  json hdf5 = job;
  hdf5["output"]["format"] = "hdf5";
  hdf5.erase("checkpoint");
  const json h5 = run_job(folder, "h5", hdf5);
  CHECK(h5["counts"]["completed"] == 8);
  CHECK(std::filesystem::file_size(folder / "h5" / "results.h5") > 0);
}

TEST_CASE("a model given by H: a convergence study finds each scheme's order against a reference run") {
  const json job = {{"model", {{"plugin", "henon_heiles"}}},
                    {"initial", {{"q", {0.0, 0.1}}, {"p", {0.45, 0.0}}}},
                    {"time", {{"t_end", 10}}},
                    {"study",
                     {{"reference_run", {{"scheme", "gauss"}, {"stages", 3}, {"steps", {4000}}}},
                      {"integrators",
                       {{{"scheme", "gauss"}, {"stages", 2}, {"steps", {100, 200, 400}}},
                        {{"scheme", "implicit_midpoint"}, {"steps", {100, 200, 400}}},
                        {{"scheme", "tao"}, {"order", "4"}, {"steps", {400, 800, 1600}}}}}}}};
  TemporaryFolder folder;
  const auto file = write_job(folder / "study.json", job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "study").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  CHECK(read_json(folder / "study" / "summary.json")["hamiltonian"] == "general");
  const auto rows = parse_csv(read_text(folder / "study" / "convergence.csv"));
  REQUIRE(rows.size() == 10);
  const auto& header = rows[0];
  const auto column = static_cast<std::size_t>(std::find(header.begin(), header.end(), "phase_error") - header.begin());
  REQUIRE(column < header.size());
  // The observed order between the last two step counts: log2 of the error ratio, 4, 2 and 4 (Tao's scheme reaches
  // its order at smaller steps).
  const double expected[] = {4.0, 2.0, 4.0};
  for (std::size_t scheme = 0; scheme < 3; ++scheme) {
    const double coarse = std::stod(rows[2 + 3 * scheme][column]), fine = std::stod(rows[3 + 3 * scheme][column]);
    CAPTURE(scheme);
    CHECK(std::log2(coarse / fine) == doctest::Approx(expected[scheme]).epsilon(0.05));
  }
}

}  // namespace test_host_general_hamiltonian
