// The fused path (plugin_abi.h integrate): a chunk of steps run inside the plugin by the core's Integrator on the
// compiled-in model must give the states and evaluation counts of the host stepping through grad_T and grad_V,
// bit for bit, for every scheme and form, one state and several, split into chunks anywhere and mixed with host
// steps (the first-same-as-last gradient crosses the ABI both ways). And whole runs (run_job) must write the same
// trajectory.csv and summary.json with the fused path on and off, including a diverging state, a failing plugin,
// checkpoints and energy evaluations in the middle of a run; a plugin without integrate runs on the host path.
#include <doctest/doctest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core/integrator.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/runner.hpp"

using nlohmann::json;
using namespace nonsep;
using namespace nonsep::host;
using namespace nonsep::host_testing;

namespace {

// The step size, out of the compiler's sight: with a literal, GCC folds std::cbrt(dt) of an inlined basic step
// at compile time (correctly rounded, by MPFR) where the plugin calls the C library's cbrt at run time, and the
// last bits differ. A job's dt is a run-time value on both sides.
volatile double step_size = 0.01;

bool same_bits(const PhaseSpaceBatch& a, const PhaseSpaceBatch& b) {
  return a.count() == b.count() && a.dimension() == b.dimension() &&
         std::memcmp(a.q().data(), b.q().data(), a.q().size() * sizeof(double)) == 0 &&
         std::memcmp(a.p().data(), b.p().data(), a.p().size() * sizeof(double)) == 0;
}

struct SchemeCase {
  const char* scheme;
  Fraction order;
};

const SchemeCase scheme_cases[] = {{"basic", Fraction(2, 3)}, {"triplet", Fraction(4, 3)}, {"triplet", Fraction(2)},
                                   {"mpe", Fraction(4, 3)},   {"mpe", Fraction(2)}};

PhaseSpaceBatch states(std::size_t n, std::size_t count) {
  PhaseSpaceBatch x(n, count);
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t i = 0; i < n; ++i) {
      x.q(b)[i] = 0.3 + 0.1 * static_cast<double>(b) + 0.05 * static_cast<double>(i);
      x.p(b)[i] = 0.5 + 0.1 * static_cast<double>(b) + 0.1 * static_cast<double>(i);
    }
  return x;
}

// Runs the chunks of `chunks` on x: through the plugin's integrate() where `fused(k)` says so for chunk k, step by
// step through grad_T and grad_V otherwise.
template <class Fused>
void run_chunks(const PluginModel& model, Integrator& integrator, PhaseSpaceBatch& x, double dt,
                const std::vector<std::uint64_t>& chunks, Fused fused) {
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    if (fused(k)) {
      model.integrate(integrator, x, dt, chunks[k]);
    } else {
      for (std::uint64_t s = 0; s < chunks[k]; ++s) integrator.step(model, x, dt);
    }
  }
}

// Runs `job` in-process with the fused path on or off; returns trajectory.csv (or "") and summary.json without
// wall_seconds.
std::pair<std::string, json> run_in_process(const TemporaryFolder& folder, const std::string& name, json job,
                                            bool fused) {
  job["output"]["directory"] = name + (fused ? "-fused" : "-host");
  const auto file = write_job(folder / (name + ".json"), job);
  const LoadedJob loaded = load_job(file);
  RunOptions options;
  options.output_directory = loaded.job.output_directory;
  options.threads = 1;
  options.fused = fused;
  RunOutcome outcome = run_job(loaded, options);
  json summary = read_json(options.output_directory / "summary.json");
  summary.erase("wall_seconds");  // and the paths, which differ
  summary.erase("job");
  summary["output"].erase("directory");
  const auto csv = options.output_directory / "trajectory.csv";
  return {std::filesystem::exists(csv) ? read_text(csv) : std::string(), summary};
}

json state(double q, double p) { return {{"q", {q}}, {"p", {p}}}; }

json paper1d_job(json initial, json integrator, std::uint64_t steps) {
  return {{"model", {{"plugin", "paper1d"}, {"parameters", json::object()}}},
          {"integrator", std::move(integrator)},
          {"initial", std::move(initial)},
          {"time", {{"dt", 0.01}, {"steps", steps}}},
          {"output", {{"every", 7}, {"energy_every", 3}}},
          {"checkpoint", {{"every_steps", 5}}}};
}

}  // namespace

TEST_CASE("fused path: states and evaluation counts equal the host path bit for bit, every scheme, form and split") {
  use_test_plugins();
  for (const char* plugin_name : {"paper1d", "radial"}) {
    const Plugin plugin = load_plugin(plugin_name, ".");
    const PluginModel model = plugin.create(json::object());
    REQUIRE(plugin.has_integrate());
    REQUIRE(model.can_integrate());
    CHECK(plugin.metadata()["capabilities"]["integrate"] == true);
    for (const auto& c : scheme_cases)
      for (const HamiltonianForm form : {HamiltonianForm::TTV, HamiltonianForm::VVT})
        for (const std::size_t count : {std::size_t{1}, std::size_t{3}}) {
          CAPTURE(std::string(plugin_name));
          CAPTURE(std::string(c.scheme));
          CAPTURE(c.order.to_string());
          CAPTURE(form == HamiltonianForm::TTV ? "TTV" : "VVT");
          CAPTURE(count);
          IntegratorSpec spec;
          spec.scheme = c.scheme;
          spec.order = c.order;
          spec.form = form;
          spec.t2 = -2.0;
          const double dt = step_size;
          const std::vector<std::uint64_t> chunks{1, 4, 7, 2, 1, 3};
          const PhaseSpaceBatch start = states(model.dimension(), count);

          std::string stage = "host";
          CAPTURE(stage);
          Integrator host(spec);
          PhaseSpaceBatch x = start;
          run_chunks(model, host, x, dt, chunks, [](std::size_t) { return false; });

          stage = "fused";
          Integrator fused(spec);
          PhaseSpaceBatch y = start;
          run_chunks(model, fused, y, dt, chunks, [](std::size_t) { return true; });
          CHECK(same_bits(x, y));
          CHECK(host.evaluations() == fused.evaluations());

          // Alternating: the cache goes into the plugin from host steps and back out to them.
          for (const int first : {0, 1}) {
            stage = "mixed " + std::to_string(first);
            Integrator mixed(spec);
            PhaseSpaceBatch z = start;
            run_chunks(model, mixed, z, dt, chunks, [&](std::size_t k) { return k % 2 == std::size_t(first); });
            CHECK(same_bits(x, z));
            CHECK(host.evaluations() == mixed.evaluations());
          }

          // A zero-step chunk changes nothing, and one more host step after a fused chunk counts as on the host.
          stage = "after";
          model.integrate(fused, y, dt, 0);
          host.step(model, x, dt);
          fused.step(model, y, dt);
          CHECK(same_bits(x, y));
          CHECK(host.evaluations() == fused.evaluations());
        }
  }
}

TEST_CASE("fused path: a non-finite state is stepped as computed, as on the host path") {
  use_test_plugins();
  const Plugin plugin = load_plugin("paper1d", ".");
  const PluginModel model = plugin.create(json::object());
  IntegratorSpec spec;
  PhaseSpaceBatch start(1, 3);
  start.q(0)[0] = 0.5;
  start.q(1)[0] = 1e103;  // grad V overflows
  start.q(2)[0] = 1.0;
  Integrator host(spec), fused(spec);
  PhaseSpaceBatch x = start, y = start;
  const double dt = step_size;
  for (int s = 0; s < 4; ++s) host.step(model, x, dt);
  model.integrate(fused, y, dt, 4);
  CHECK(host.evaluations() == fused.evaluations());
  CHECK(std::memcmp(x.q().data(), y.q().data(), sizeof(double)) == 0);
  CHECK(std::memcmp(x.q(2).data(), y.q(2).data(), sizeof(double)) == 0);
  CHECK(!std::isfinite(y.q(1)[0]));
}

TEST_CASE("fused path: a plugin failure inside integrate is a ModelError with the plugin's message") {
  const Plugin plugin =
      load_plugin(std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/evaluation_fails.so", ".");
  const PluginModel model = plugin.create(json::object());
  REQUIRE(model.can_integrate());
  Integrator integrator{IntegratorSpec{}};
  PhaseSpaceBatch x(1, 1);
  x.q(0)[0] = 2.0;  // outside |q| < 1
  try {
    model.integrate(integrator, x, 0.01, 3);
    FAIL("integrate did not fail");
  } catch (const ModelError& error) {
    CHECK(std::string(error.what()).find("failed in integrate (evaluation failed)") != std::string::npos);
    CHECK(std::string(error.what()).find("needs |q| < 1") != std::string::npos);
  }
}

TEST_CASE("fused path: run_job writes the same files with it on and off") {
  use_test_plugins();
  TemporaryFolder folder;
  struct Case {
    std::string name;
    json job;
  };
  std::vector<Case> cases;
  for (const auto& c : scheme_cases)
    for (const char* form : {"TTV", "VVT"}) {
      json job = paper1d_job(json::array({state(0.5, 0.1), state(1.2, -0.3), state(2.0, 0.0)}),
                             {{"scheme", c.scheme}, {"order", c.order.to_string()}, {"t2", -2.0}}, 40);
      job["hamiltonian"] = form;
      cases.push_back({std::string(c.scheme) + "-" + c.order.to_string() + "-" + form, job});
    }
  for (auto& c : cases)
    for (auto& ch : c.name)
      if (ch == '/') ch = '_';
  // One state: the case of figure 1.
  cases.push_back({"single", paper1d_job(json::array({state(2.0, 0.0)}), {{"scheme", "basic"}}, 100)});
  // A state that diverges in the middle of a chunk, beside two that complete: the replay finds step and variable.
  cases.push_back({"diverging", paper1d_job(json::array({state(0.5, 0.0), state(1e103, 0.0), state(1.0, 0.0)}),
                                             {{"scheme", "triplet"}, {"order", "4/3"}}, 40)});
  // A plugin failing mid-run (SDK plugin: it has integrate): the replay finds the failing step.
  {
    json job = paper1d_job(json::array({state(0.5, 0.5), state(0.1, 0.0)}), {{"scheme", "triplet"}, {"order", "4/3"}},
                           200);
    job["model"]["plugin"] = std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/evaluation_fails.so";
    cases.push_back({"failing", job});
  }
  // A plugin without integrate (written against the C ABI): the host path, the same either way.
  {
    json job = paper1d_job(json::array({state(0.5, 0.5)}), {{"scheme", "basic"}}, 30);
    job["model"]["plugin"] = "blowup";
    job["model"]["parameters"] = {{"nan_after", 60}};
    cases.push_back({"no_integrate", job});
  }
  for (const auto& c : cases) {
    CAPTURE(c.name);
    const auto [csv_fused, summary_fused] = run_in_process(folder, c.name, c.job, true);
    const auto [csv_host, summary_host] = run_in_process(folder, c.name, c.job, false);
    CHECK(csv_fused == csv_host);
    CHECK(summary_fused.dump() == summary_host.dump());
    CHECK(!csv_fused.empty());
    if (c.name == "diverging") {
      CHECK(summary_fused["trajectories"][1]["status"] == "diverged");
      CHECK(summary_fused["trajectories"][1]["diverged"]["step"] == 1);
      CHECK(summary_fused["trajectories"][0]["status"] == "completed");
    }
    if (c.name == "failing") CHECK(summary_fused["trajectories"][0]["status"] == "failed");
    if (c.name == "no_integrate") CHECK(summary_fused["trajectories"][0]["status"] == "diverged");
  }
}

TEST_CASE("fused path: NONSEP_FUSED=0 switches it off for nonsep run, with the same files") {
  TemporaryFolder folder;
  json job = paper1d_job(json::array({state(2.0, 0.0), state(0.7, 0.2)}), {{"scheme", "mpe"}, {"order", "2"}}, 60);
  job["output"]["directory"] = "on";
  write_job(folder / "on.json", job);
  job["output"]["directory"] = "off";
  write_job(folder / "off.json", job);
  const Result on = run_nonsep({"run", "--quiet", (folder / "on.json").string()}, folder.path());
  ::setenv("NONSEP_FUSED", "0", 1);
  const Result off = run_nonsep({"run", "--quiet", (folder / "off.json").string()}, folder.path());
  ::unsetenv("NONSEP_FUSED");
  CHECK(on.status == 0);
  CHECK(off.status == 0);
  CHECK(read_text(folder / "on/trajectory.csv") == read_text(folder / "off/trajectory.csv"));
  json a = read_json(folder / "on/summary.json"), b = read_json(folder / "off/summary.json");
  for (json* summary : {&a, &b}) {
    summary->erase("wall_seconds");
    summary->erase("job");
    (*summary)["output"].erase("directory");
  }
  CHECK(a.dump() == b.dump());
}

