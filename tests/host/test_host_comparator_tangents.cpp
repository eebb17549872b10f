// Lyapunov exponents and MEGNO with the comparator schemes (gauss, implicit_midpoint, tao) through the `nonsep`
// executable on paper2d: the same files for any --threads, killed and resumed bit for bit (Tao's copies and their
// tangents are checkpointed), the host's exponents those of the core's tangent maps, the leading exponent of the
// chaotic orbit converging as dt shrinks, and the refusal of a plugin without the directional derivative of grad H.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "paper2d/paper2d.hpp"

namespace test_host_comparator_tangents {

using namespace nonsep::host_testing;

namespace {

using PluginPaper2D = nonsep::sdk::ModelAdapter<::Paper2D>;

json comparator(const std::string& scheme) {
  if (scheme == "gauss") return {{"scheme", "gauss"}, {"stages", 3}};
  if (scheme == "tao") return {{"scheme", "tao"}, {"order", 4}};
  return {{"scheme", scheme}};
}

// Orbits of paper2d on the shell H = 7 (the dynamics examples' coupling), with k = 4 vectors (the whole spectrum),
// renormalised every 5 steps, series every 100 steps, and MEGNO.
json ensemble_job(const std::string& scheme, std::uint64_t steps) {
  return {{"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.2}}}}},
          {"integrator", comparator(scheme)},
          {"initial",
           {{"grid",
             {{"q", {{{"from", -0.8}, {"to", 0.8}, {"count", 6}}, 0.0}},
              {"p", {{{"from", -1.5}, {"to", 1.5}, {"count", 5}}, 0.0}}}},
            {"energy", 7.0},
            {"solve_for", "p1"}}},
          {"time", {{"dt", 0.005}, {"steps", steps}}},
          {"output", {{"every", 100}}},
          {"analysis", {{"lyapunov", {{"vectors", 4}, {"renormalize_every", 5}, {"every", 100}}}, {"megno", true}}}};
}

// The cells of column `name` of trajectories.csv.
std::vector<double> column(const std::filesystem::path& file, const std::string& name) {
  const auto rows = read_csv(file);
  REQUIRE(rows.size() > 1);
  std::size_t c = 0;
  while (c < rows[0].size() && rows[0][c] != name) ++c;
  REQUIRE(c < rows[0].size());
  std::vector<double> values;
  for (std::size_t r = 1; r < rows.size(); ++r) values.push_back(std::strtod(rows[r][c].c_str(), nullptr));
  return values;
}

const char* const schemes[] = {"gauss", "implicit_midpoint", "tao"};

}  // namespace

TEST_CASE("comparators with tangent vectors: --threads 1 and 2 write the same files, byte for byte") {
  for (const char* scheme : schemes) {
    CAPTURE(scheme);
    TemporaryFolder folder;
    const json job = ensemble_job(scheme, 400);
    const auto one = run_named(folder, "one", job, {"--threads", "1"});
    INFO("stderr: " << one.err);
    REQUIRE(one.status == 0);
    REQUIRE(run_named(folder, "two", job, {"--threads", "2"}).status == 0);
    for (const char* file : {"lyapunov.csv", "trajectories.csv", "trajectory.csv"}) {
      CAPTURE(file);
      CHECK(read_text(folder / "one" / file) == read_text(folder / "two" / file));
    }
    const auto sums = column(folder / "one/trajectories.csv", "lyapunov0");
    CHECK(sums.size() > 10);
  }
}

TEST_CASE("comparators with tangent vectors: killed and resumed, bit for bit") {
  for (const char* scheme : schemes) {
    CAPTURE(scheme);
    TemporaryFolder reference;
    json job = ensemble_job(scheme, 6000);
    job["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
    REQUIRE(run_named(reference, "out", job).status == 0);
    TemporaryFolder folder;
    const auto file = write_job(folder / "job.json", job);
    const auto step = kill_after_checkpoint(file, folder / "out", 1000, folder.path());
    INFO("killed after the checkpoint at step " << step);
    CHECK(step < 6000);
    const auto resumed =
        run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
    INFO("stderr: " << resumed.err);
    REQUIRE(resumed.status == 0);
    for (const char* name : {"lyapunov.csv", "trajectories.csv", "trajectory.csv"}) {
      CAPTURE(name);
      CHECK(read_text(folder / "out" / name) == read_text(reference / "out" / name));
    }
  }
}

TEST_CASE("the host's exponents with a comparator are the core tangent map's, bit for bit") {
  for (const char* scheme : schemes) {
    CAPTURE(scheme);
    TemporaryFolder folder;
    json job = {{"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.2}}}}},
                {"integrator", comparator(scheme)},
                {"initial", {{"q", {0.5, 0.0}}, {"p", {0.0, 2.5}}}},
                {"time", {{"dt", 0.005}, {"steps", 400}}},
                {"output", {{"every", 0}}},
                {"analysis", {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 1}}}}}};
    run_job(folder, "out", job);
    const double host = column(folder / "out/trajectories.csv", "lyapunov0").at(0);

    const auto model = PluginPaper2D::from_json(R"({"coupling": 0.2})");
    nonsep::IntegratorSpec spec{scheme};
    if (std::string(scheme) == "gauss") spec.options = nonsep::GaussOptions{3};
    if (std::string(scheme) == "tao") spec.options = nonsep::TaoOptions{nonsep::Fraction(4)};
    const double q[] = {0.5, 0.0}, p[] = {0.0, 2.5};
    auto x = nonsep::PhaseSpaceBatch::single(q, p);
    nonsep::PhaseSpaceBatch v(2, 1);
    // The host's first vector (tangent_block.hpp): (1, 1/2, 1/3, 1/4), normalised by LyapunovExponents::start.
    v.q()[0] = 1.0, v.q()[1] = 0.5, v.p()[0] = 1.0 / 3.0, v.p()[1] = 0.25;
    nonsep::TangentIntegrator integrator(spec, 1);
    nonsep::LyapunovExponents exponents(1, 1);
    std::vector<nonsep::LyapunovRecord> records(1);
    std::vector<double> growth(1);
    exponents.start(v, records);
    volatile double opaque_dt = 0.005;
    for (int s = 0; s < 400; ++s) {
      integrator.step(model, x, v, opaque_dt);
      exponents.after_step(v, records, opaque_dt, growth);
    }
    CHECK(host == records[0].exponent(0));
  }
}

TEST_CASE("a comparator's tangent vectors with a plugin without hvp_H are refused, naming /analysis and hvp_H") {
  TemporaryFolder folder;
  for (const char* key : {"lyapunov", "megno"}) {
    CAPTURE(key);
    // A plugin of ABI version 4 (Hessians and third derivatives, no hvp_H).
    json job = {{"model", {{"plugin", std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/kernel_other_version.so"}}},
                {"integrator", {{"scheme", "gauss"}}},
                {"initial", {{"q", {0.5}}, {"p", {0.1}}}},
                {"time", {{"dt", 0.005}, {"steps", 10}}},
                {"analysis", {{key, std::string(key) == "megno" ? json(true) : json::object()}}}};
    const auto result = run_named(folder, key, job);
    CHECK(result.status == 2);
    CHECK(result.err.find(std::string("/analysis/") + key) != std::string::npos);
    CHECK(result.err.find("which has no directional derivative of grad H (hvp_H, plugin ABI version 5; it is of "
                          "version 4)") != std::string::npos);
    // The same plugin runs the scheme without tangent vectors.
    job.erase("analysis");
    CHECK(run_named(folder, std::string(key) + "_plain", job).status == 0);
  }
}

}  // namespace test_host_comparator_tangents
