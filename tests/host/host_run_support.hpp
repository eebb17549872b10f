#pragma once
// Helpers shared by the tests of the `nonsep` executable on job files (test_host_run.cpp, test_host_stops.cpp,
// test_host_energy.cpp, test_host_threads.cpp, test_host_commands.cpp): the core run directly on the paper1d
// plugin's model class for bit-for-bit comparisons, and short job files for paper1d and the blowup test plugin.
#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "host_test_support.hpp"
#include "nonsep/core.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "paper1d/paper1d.hpp"

namespace nonsep::host_testing {

using nlohmann::json;

inline constexpr double quarter_period = 0.3863765573361232;

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

inline nonsep::IntegratorSpec triplet_43(double t2 = -2.0) {
  return {"triplet", nonsep::ChinOptions{nonsep::Fraction(4, 3), t2}};
}

// Runs `job` (written to folder/name.json) with --output folder/name and returns the summary.
inline json run_job(const TemporaryFolder& folder, const std::string& name, const json& job, int expected_status = 0) {
  const auto file = write_job(folder / (name + ".json"), job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == expected_status);
  return read_run(folder / name);
}

inline double number(const json& value) { return value.get<double>(); }

inline json paper1d_job(json initial, json time,
                        json integrator = {{"scheme", "triplet"}, {"order", "4/3"}, {"t2", -2.0}}) {
  return {{"model", {{"plugin", "paper1d"}}},
          {"integrator", std::move(integrator)},
          {"initial", std::move(initial)},
          {"time", std::move(time)},
          {"output", {{"every", 1}}}};
}

inline json blowup_job(json initial, json parameters = json::object(), std::string plugin = "blowup") {
  return {{"model", {{"plugin", std::move(plugin)}, {"parameters", std::move(parameters)}}},
          {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
          {"initial", std::move(initial)},
          {"time", {{"dt", 0.001}, {"steps", 40}}},
          {"output", {{"every", 5}}}};
}

inline json state(double q, double p) { return {{"q", {q}}, {"p", {p}}}; }

// summary.json without what legitimately differs between two runs of one job: the time taken and the folder.
inline json comparable(json summary) {
  summary.erase("wall_seconds");
  summary["output"].erase("directory");
  return summary;
}

}  // namespace nonsep::host_testing
