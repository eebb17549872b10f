// Energies in the `nonsep` executable's outputs: when they are sampled and summarised, and what the outputs say
// when the plugin has no Hessians.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/progress_bar.hpp"
#include "support/nan_aware.hpp"

namespace test_host_energy {

using nlohmann::json;
using namespace nonsep::host_testing;

TEST_CASE("without Hessians the energy is null, the CSV's energy cells empty, and the summary says why") {
  TemporaryFolder folder;
  const json summary =
      run_job(folder, "no-energy", blowup_job(state(1.0, 0.5), json::object(), "blowup_gradients_only"));
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

namespace {

// The largest |relative_energy_error| over the rows of a trajectory.csv (the numbers round-trip exactly).
double largest_csv_energy_error(const std::filesystem::path& csv) {
  double largest = 0.0;
  for (const auto& row : read_csv(csv))
    if (row[0] != "trajectory" && !row.back().empty())
      largest = nonsep::testing::max_or_nan(largest, std::abs(std::stod(row.back())));
  return largest;
}

}  // namespace

TEST_CASE("energy: H at step 0, the samples, every energy_every-th step and the end, max_abs over exactly those") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["time"] = {{"dt", 0.005}, {"steps", 120}};  // past the quarter period: the error is largest mid-run
  job["output"] = {{"every", 1}};
  const json all = run_job(folder, "every1", job);
  const json& all_energy = all["trajectories"][0]["energy"];
  CHECK(number(all_energy["relative_error_max_abs"]) == largest_csv_energy_error(folder / "every1" / "trajectory.csv"));
  CHECK(all["energy"]["evaluated_at"].get<std::string>().find("every written sample") != std::string::npos);
  CHECK(number(all["energy"]["largest_relative_error"]["value"]) == number(all_energy["relative_error_max_abs"]));

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

TEST_CASE("analysis.max_relative_energy_error retires a trajectory past the bound as inaccurate, the others go on") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job["initial"] = json::array({state(0.5, 0.0), state(2.0, 0.0)});  // |dH/H0| ~ 5e-3 and ~ 3.6e-2 at dt = 0.005
  job["output"] = {{"every", 1}};
  job["analysis"] = {{"max_relative_energy_error", 0.02}};
  const json summary = run_job(folder, "bounded", job, 1);
  CHECK(summary["status"] == "inaccurate");
  CHECK(summary["counts"]["inaccurate"] == 1);
  CHECK(summary["counts"]["completed"] == 1);
  const json& small = summary["trajectories"][0];
  const json& large = summary["trajectories"][1];
  CHECK(small["status"] == "completed");
  CHECK(number(small["energy"]["relative_error_max_abs"]) <= 0.02);
  CHECK(large["status"] == "inaccurate");
  const auto step = large["stop"]["step"].get<std::uint64_t>();
  CHECK(large["final"]["step"] == step);  // it stops where the bound was crossed
  CHECK(std::abs(number(large["energy"]["relative_error_final"])) > 0.02);
  CHECK(large["message"].get<std::string>().find("exceeds analysis.max_relative_energy_error = 0.02") !=
        std::string::npos);
  // Without the bound the same trajectory completes, and passes the bound exactly at that step first.
  job.erase("analysis");
  const json free = run_job(folder, "free", job);
  CHECK(free["trajectories"][1]["status"] == "completed");
  for (const auto& row : read_csv(folder / "free" / "trajectory.csv")) {
    if (row[0] != "1" || row.back().empty()) continue;
    if (std::stoull(row[1]) < step) CHECK(std::abs(std::stod(row.back())) <= 0.02);
    if (std::stoull(row[1]) == step) CHECK(std::abs(std::stod(row.back())) > 0.02);
  }
}

TEST_CASE("the completion line names the largest relative energy error, and a warning comes above 0.1") {
  TemporaryFolder folder;
  json job = quickstart_job();
  const auto file = write_job(folder / "q.json", job);
  auto result = run_nonsep({"run", "--output", (folder / "q").string(), file.string()}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("largest |dH/H0| 0.03592251724420663 (trajectory 0)") != std::string::npos);
  CHECK(result.err.find("warning") == std::string::npos);
  job["integrator"] = {{"scheme", "basic"}, {"t2", -2.0}};
  job["time"] = {{"dt", 0.05}, {"steps", 40}};  // the basic step at a coarse dt: |dH/H0| well above 0.1
  write_job(file, job);
  result = run_nonsep({"run", "--quiet", "--output", (folder / "coarse").string(), file.string()}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.err.find("nonsep: warning: the relative energy error |dH/H0| reached 0.312") != std::string::npos);
}

TEST_CASE("the largest |dH/H0| includes the last state of a trajectory that diverged, between two samples") {
  TemporaryFolder folder;
  // Triplet 8/3 with 16 steps over the quarter period overflows after a few steps (the SDK passes the non-finite
  // gradient on); without samples, H is evaluated at step 0 and at the last finite state only.
  json job = paper1d_job(state(2.0, 0.0), {{"t_end", quarter_period}, {"dt", quarter_period / 16}},
                         {{"scheme", "triplet"}, {"order", "8/3"}, {"t2", -2.0}});
  job["output"] = {{"every", 0}};
  const auto file = write_job(folder / "diverging.json", job);
  const auto result = run_nonsep({"run", "--output", (folder / "diverging").string(), file.string()}, folder.path());
  REQUIRE(result.status == 1);
  const json summary = read_run(folder / "diverging");
  const json& trajectory = summary["trajectories"][0];
  REQUIRE(trajectory["status"] == "diverged");
  REQUIRE(trajectory["final"]["step"].get<std::uint64_t>() >= 1);
  const double final_error = std::abs(number(trajectory["energy"]["relative_error_final"]));
  CHECK(final_error > 0.0);
  CHECK(number(trajectory["energy"]["relative_error_max_abs"]) == final_error);
  CHECK(number(summary["energy"]["largest_relative_error"]["value"]) == final_error);
  CHECK((result.out + result.err)
            .find("largest |dH/H0| " + nonsep::host::format_number(final_error) + " (trajectory 0)") !=
        std::string::npos);
}

TEST_CASE("the progress line's energy error: n/a while H was evaluated at step 0 only, then the largest so far") {
  using nonsep::host::EnergyErrorObserver;
  CHECK(nonsep::host::energy_error_text(std::nullopt, ", ").empty());  // no H: nothing shown
  CHECK(nonsep::host::energy_error_text(std::nan(""), ", ") == ", max |dH/H0| n/a");
  CHECK(nonsep::host::energy_error_text(1.2e-9, "  ") == "  max |dH/H0| 1.20e-09");
  // Two trajectories with H0 = 2; H evaluated at step 0 (error 0), then at a sample, step 10.
  EnergyErrorObserver energy(2, 0, std::nullopt);
  nonsep::host::TrajectoryRecord record;
  record.energy_initial = 2.0;
  const std::vector<double> q{0.0}, p{0.0};
  const auto event = [&](std::uint64_t step, double h) {
    const std::vector<nonsep::host::StateView> states{{0, q, p, h, &record}, {1, q, p, 2.0, &record}};
    std::vector<nonsep::host::StoppedTrajectory> retire;
    energy.on_event({step, 0.1 * static_cast<double>(step), states, true, &retire});
  };
  event(0, 2.0);
  REQUIRE(energy.largest());
  CHECK(energy.largest()->value == 0.0);
  CHECK_FALSE(energy.evaluated_after_start());  // a 0.00e+00 here would be the error nowhere measured
  event(10, 2.0 + 2e-6);
  CHECK(energy.evaluated_after_start());
  CHECK(energy.largest()->value == doctest::Approx(1e-6));
  // Saved and restored with a checkpoint.
  EnergyErrorObserver resumed(2, 0, std::nullopt);
  resumed.restore(energy.save());
  CHECK(resumed.evaluated_after_start());
}

TEST_CASE("the time left is estimated from the steps this process ran: after a resume, those since the resumed one") {
  using nonsep::host::remaining_seconds;
  CHECK(remaining_seconds(10.0, 0, 50, 100) == 10.0);
  // Resumed at step 90 of 100: 5 steps took 10 s, 5 are left: 10 s (not 10 s * 5 / 95).
  CHECK(remaining_seconds(10.0, 90, 95, 100) == 10.0);
  CHECK(remaining_seconds(10.0, 90, 90, 100) == 0.0);  // nothing measured yet
  CHECK(remaining_seconds(3.0, 10, 100, 100) == 0.0);
}

}  // namespace test_host_energy
