// Convergence studies (/study) and the closest-return analysis (/analysis): the power-law fit on its own, and the
// built executable on small paper1d jobs, compared with the core run directly.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <regex>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/study/convergence_study.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "paper1d/paper1d.hpp"

namespace test_host_study {

using json = nlohmann::json;
using namespace nonsep::host_testing;

namespace {

constexpr double quarter_period = 0.3863765573361232;
constexpr double p_at_quarter = -1.5723027555148466;

using PluginPaper1D = nonsep::sdk::ModelAdapter<::Paper1D>;

json study_job(json integrators, json steps) {
  return {{"model", {{"plugin", "paper1d"}}},
          {"initial", {{"q", {2.0}}, {"p", {0.0}}}},
          {"time", {{"t_end", quarter_period}}},
          {"study",
           {{"steps", std::move(steps)},
            {"reference", {{"q", {0.0}}, {"p", {p_at_quarter}}}},
            {"integrators", std::move(integrators)}}}};
}

struct Finished {
  int status;
  json summary;
  std::vector<std::vector<std::string>> rows;
  std::string out, err;  // the console report
};

Finished run_study_job(const TemporaryFolder& folder, const std::string& name, const json& job, bool quiet = true) {
  const auto file = write_job(folder / (name + ".json"), job);
  std::vector<std::string> args{"run", "--output", (folder / name).string(), file.string()};
  if (quiet) args.insert(args.begin() + 1, "--quiet");
  const auto result = run_nonsep(args, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(std::filesystem::exists(folder / name / "summary.json"));
  return {result.status, read_json(folder / name / "summary.json"), read_csv(folder / name / "convergence.csv"),
          result.out, result.err};
}

// The console report of a study, as it must follow from its summary.json: the status line, one line per fit and
// one per run that diverged or failed.
std::string expected_report(const json& summary, const std::filesystem::path& directory) {
  const json& runs = summary["study"]["runs"];
  const std::size_t integrators = summary["fits"].size(), completed = runs["completed"].get<std::size_t>();
  std::string text = summary["status"].get<std::string>() + ": study of " + std::to_string(integrators) +
                     (integrators == 1 ? " integrator, " : " integrators, ") + std::to_string(completed) +
                     (completed == 1 ? " run" : " runs") + " completed";
  for (const char* other : {"diverged", "failed", "interrupted"})
    if (runs[other].get<std::size_t>() > 0) text += ", " + std::to_string(runs[other].get<std::size_t>()) + " " + other;
  text += "; results in " + directory.string() + "\n";
  const auto four_digits = [](double x) {
    char digits[32];
    std::snprintf(digits, sizeof digits, "%#.4g", x);
    return std::string(digits);
  };
  for (const auto& fit : summary["fits"])
    text += "  " + fit["integrator"].get<std::string>() + ": energy error exponent " +
            (fit["exponent"].is_null() ? std::string("(no fit)") : four_digits(fit["exponent"].get<double>())) +
            " (nominal " + fit["order"].get<std::string>() + " = " +
            four_digits(fit["nominal_exponent"].get<double>()) + ")\n";
  return text;
}

}  // namespace

TEST_CASE("fit_power_law recovers c dt^n, skips zero and non-finite errors, and needs two distinct dt") {
  const std::vector<double> dt{0.1, 0.05, 0.025, 0.0125, 0.001};
  std::vector<double> error;
  for (double h : dt) error.push_back(-2.0 * std::pow(h, 2.0 / 3.0));
  error.back() = std::numeric_limits<double>::quiet_NaN();
  const auto fit = nonsep::host::fit_power_law(dt, error);
  REQUIRE(fit);
  CHECK(fit->exponent == doctest::Approx(2.0 / 3.0).epsilon(1e-12));
  CHECK(fit->constant == doctest::Approx(2.0).epsilon(1e-12));
  CHECK(fit->points == 4);
  const std::vector<double> one_error{1e-3, 0.0, std::numeric_limits<double>::infinity()};
  CHECK_FALSE(nonsep::host::fit_power_law(std::vector<double>{0.1, 0.2, 0.3}, one_error));
  CHECK_FALSE(nonsep::host::fit_power_law(std::vector<double>{0.1, 0.1}, std::vector<double>{1e-3, 2e-3}));
}

TEST_CASE("round_off_floor_start: where the errors stop falling as the order says, below 1e-8, or below 5e-14") {
  using nonsep::host::round_off_floor_start;
  std::vector<double> dt, clean, floored;
  for (int k = 0; k < 7; ++k) {
    dt.push_back(0.1 / std::pow(2.0, k));
    clean.push_back(-3e-3 * std::pow(dt.back() / 0.1, 4.0));  // 3e-3 down to 1.8e-10, slope 4 throughout
    floored.push_back(-std::max(3e-3 * std::pow(dt.back() / 0.1, 4.0), 1e-9 * (k % 2 ? 1.3 : 1.0)));
  }
  CHECK(round_off_floor_start(dt, clean, 4.0) == dt.size());
  // 3e-3 ... 2.9e-9 with slope 4, then the floor 1e-9 at k = 6 (1.8e-10 without it): the local slope from k = 5 to
  // k = 6 is 1.5 < 4 / 2, so k = 5, only 2.9 times the floor, is left out too.
  CHECK(round_off_floor_start(dt, floored, 4.0) == 5);
  const std::vector<double> last_only{dt[0], dt[1], dt[2]}, errors{1e-9, 6.25e-11, 5e-11};
  CHECK(round_off_floor_start(last_only, errors, 4.0) == 1);  // 6.25e-11 -> 5e-11: slope 0.3
  floored[4] = 4e-14;                                         // below 5e-14: round-off whatever the slope
  CHECK(round_off_floor_start(dt, floored, 4.0) == 4);
  // Above 1e-8 a slow fall is the method's (pre-asymptotic), not round-off.
  const std::vector<double> large{1e-2, 9e-3, 8e-3};
  CHECK(round_off_floor_start(std::vector<double>{0.1, 0.05, 0.025}, large, 4.0) == 3);
}

TEST_CASE("a study's rows are the core's runs bit for bit, and its fit is the slope through them") {
  TemporaryFolder folder;
  const json integrators = {{{"scheme", "basic"}, {"t2", -2.0}},
                            {{"scheme", "mpe"}, {"order", "2"}, {"t2", -2.0}, {"steps", {256, 512, 1024}}}};
  const auto run = run_study_job(folder, "study", study_job(integrators, {128, 256}));
  REQUIRE(run.status == 0);
  REQUIRE(run.rows.size() == 1 + 2 + 3);
  CHECK(run.rows[0] == std::vector<std::string>{"integrator", "scheme", "order", "t2", "symplectic", "dt", "steps",
                                                "basic_steps", "grad_T", "grad_V", "relative_energy_error",
                                                "phase_error", "status", "family", "grad_H",
                                                "max_abs_relative_energy_error"});
  const PluginPaper1D model;
  nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
  const double q0[] = {2.0}, p0[] = {0.0};
  const double h0 = energy.evaluate_one(model, nonsep::PhaseSpaceBatch::single(q0, p0));
  for (std::size_t r = 1; r < run.rows.size(); ++r) {
    const auto& row = run.rows[r];
    INFO("row " << r);
    const bool basic = row[0] == "basic";
    CHECK(row[0] == (basic ? "basic" : "mpe 2"));
    const std::uint64_t steps = std::stoull(row[6]);
    const double dt = quarter_period / static_cast<double>(steps);
    CHECK(std::stod(row[5]) == dt);
    nonsep::Integrator integrator(
        {basic ? "basic" : "mpe", nonsep::ChinOptions{basic ? nonsep::Fraction(2, 3) : nonsep::Fraction(2), -2.0}});
    auto x = nonsep::PhaseSpaceBatch::single(q0, p0);
    for (std::uint64_t k = 0; k < steps; ++k) integrator.step(model, x, dt);
    CHECK(std::stoull(row[7]) == steps * (basic ? 1 : 6));
    CHECK(std::stoull(row[8]) == integrator.evaluations().grad_T);
    CHECK(std::stoull(row[9]) == integrator.evaluations().grad_V);
    CHECK(std::stod(row[10]) == (energy.evaluate_one(model, x) - h0) / h0);
    const double dq = x.q(0)[0], dp = x.p(0)[0] - p_at_quarter;
    CHECK(std::stod(row[11]) == std::sqrt(dq * dq + dp * dp));
    CHECK(row[12] == "completed");
  }
  const auto& fits = run.summary["fits"];
  REQUIRE(fits.size() == 2);
  // Two points: the fit is the line through the largest |dH/H0| of each run (column 15), at least the end's.
  for (std::size_t r = 1; r < run.rows.size(); ++r)
    CHECK(std::stod(run.rows[r][15]) >= std::abs(std::stod(run.rows[r][10])));
  const double e1 = std::stod(run.rows[1][15]), e2 = std::stod(run.rows[2][15]);
  CHECK(fits[0]["exponent"].get<double>() == doctest::Approx(std::log(e1 / e2) / std::log(2.0)).epsilon(1e-12));
  CHECK(fits[0]["constant"].get<double>() < 0.0);  // the basic step loses energy here
  CHECK(fits[0]["n_points"] == 2);
  CHECK(fits[0]["steps_from"] == "study.steps");
  CHECK(fits[1]["steps_from"] == "integrator.steps");
  CHECK(fits[1]["steps_min"] == 256);
  CHECK(fits[1]["steps_max"] == 1024);
  CHECK(std::abs(fits[1]["exponent"].get<double>() - 2.0) < 0.3);
  CHECK(std::abs(fits[1]["phase_exponent"].get<double>() - 2.0) < 0.3);
  // Without --quiet the report on stdout says what summary.json says.
  const auto loud = run_study_job(folder, "study_loud", study_job(integrators, {128, 256}), false);
  CHECK(loud.out == expected_report(loud.summary, folder / "study_loud"));
  CHECK(loud.err.empty());
  // One integrator is one, not "1 integrators".
  const auto one = run_study_job(folder, "study_one", study_job(json::array({integrators[0]}), {128, 256}), false);
  CHECK(one.out == expected_report(one.summary, folder / "study_one"));
  CHECK(one.out.find(": study of 1 integrator, 2 runs completed; results in ") != std::string::npos);
}

TEST_CASE("a study run that blows up is a diverged row, left out of the fit, and the exit status is 1") {
  TemporaryFolder folder;
  // With 16 steps triplet 8/3 overflows; the SDK passes the non-finite gradient on, so the run diverges.
  const json integrators = {{{"scheme", "triplet"}, {"order", "8/3"}, {"t2", -2.0}}};
  const auto run = run_study_job(folder, "failing", study_job(integrators, {16, 1024}));
  CHECK(run.status == 1);
  CHECK(run.summary["status"] == "diverged");
  REQUIRE(run.rows.size() == 3);
  CHECK(run.rows[1][12] == "diverged");
  CHECK(run.rows[1][10].empty());
  CHECK(run.rows[2][12] == "completed");
  CHECK(run.summary["fits"][0]["n_points"] == 1);
  CHECK(run.summary["fits"][0]["exponent"].is_null());
  REQUIRE(run.summary["failures"].size() == 1);
  CHECK(run.summary["failures"][0]["steps"] == 16);
  // The report goes to stderr even with --quiet, and names the run that diverged.
  CHECK(run.out.empty());
  CHECK(run.err == "nonsep: " + expected_report(run.summary, folder / "failing") +
                       "nonsep: triplet 8/3 with 16 steps " +
                       "diverged: " + run.summary["failures"][0]["error"].get<std::string>() + "\n");
}

TEST_CASE("closest_return is the minimum distance to the start over every step from closest_return_after on") {
  TemporaryFolder folder;
  const json job = {{"model", {{"plugin", "paper1d"}}},
                    {"integrator", {{"scheme", "basic"}, {"t2", -2.0}}},
                    {"initial", {{{"q", {2.0}}, {"p", {0.0}}}, {{"q", {0.5}}, {"p", {0.0}}}}},
                    {"time", {{"dt", 0.005}, {"t_end", 3.0}}},
                    {"analysis", {{"closest_return_after", 1.2}}},
                    {"output", {{"every", 1}}}};
  const auto file = write_job(folder / "orbit.json", job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "orbit").string(), file.string()}, folder.path());
  REQUIRE(result.status == 0);
  const json summary = read_run(folder / "orbit");
  const auto rows = read_csv(folder / "orbit" / "trajectory.csv");
  for (std::size_t trajectory = 0; trajectory < 2; ++trajectory) {
    double q0 = 0.0, best = std::numeric_limits<double>::infinity(), best_t = -1.0;
    for (std::size_t r = 1; r < rows.size(); ++r) {
      if (std::stoul(rows[r][0]) != trajectory) continue;
      const double t = std::stod(rows[r][2]), q = std::stod(rows[r][3]), p = std::stod(rows[r][4]);
      if (std::stoul(rows[r][1]) == 0) q0 = q;
      if (t < 1.2) continue;
      const double d = std::hypot(q - q0, p);
      if (d < best) {
        best = d;
        best_t = t;
      }
    }
    const auto& closest = summary["trajectories"][trajectory]["closest_return"];
    INFO("trajectory " << trajectory);
    CHECK(closest["distance"].get<double>() == best);
    CHECK(closest["t"].get<double>() == best_t);
    CHECK(best < 5e-3);  // the orbit closes after one period
  }
  // Without /analysis there is no closest_return.
  json plain = job;
  plain.erase("analysis");
  const auto plain_file = write_job(folder / "plain.json", plain);
  REQUIRE(run_nonsep({"run", "--quiet", "--output", (folder / "plain").string(), plain_file.string()}, folder.path())
              .status == 0);
  CHECK_FALSE(read_run(folder / "plain")["trajectories"][0].contains("closest_return"));
}

TEST_CASE("the study's report: exponents to 4 significant digits, and the round-off floor left out with a warning") {
  TemporaryFolder folder;
  // MPE 4 to 4096 steps reaches the round-off of paper1d (about 1e-11, of random sign) from 512 steps on: those four
  // runs are left out and the fit over 64 .. 256 steps finds the order; triplet 4/3 on these step counts stays in its
  // asymptotic range (the control: no warning).
  json job =
      study_job({{{"scheme", "mpe"}, {"order", "4"}, {"t2", -2.5}, {"steps", {64, 128, 256, 512, 1024, 2048, 4096}}},
                 {{"scheme", "triplet"}, {"order", "4/3"}, {"t2", -2.0}, {"steps", {256, 512, 1024, 2048}}}},
                json::array());
  job["study"].erase("steps");  // each integrator has its own
  const auto file = write_job(folder / "round_off.json", job);
  const auto result = run_nonsep({"run", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO(result.out, result.err);
  CHECK(result.status == 0);
  CHECK(std::regex_search(
      result.out, std::regex(R"(  mpe 4: energy error exponent \d\.\d{3} \(nominal 4 = 4\.000\) \(see warning\)\n)")));
  CHECK(std::regex_search(result.out,
                          std::regex(R"(  triplet 4/3: energy error exponent 1\.\d{3} \(nominal 4/3 = 1\.333\)\n)")));
  CHECK(result.err.find("nonsep: warning: mpe 4: 4 runs at the round-off floor of the energy error (dt <= ") !=
        std::string::npos);
  CHECK(result.err.find("left out of the fit, which has 3 points; move its step range to larger dt (fewer steps)") !=
        std::string::npos);
  CHECK(result.err.find("mpe 4: the energy error changes sign") == std::string::npos);  // the floor's signs: left out
  CHECK(result.err.find("triplet 4/3:") == std::string::npos);
  const json summary = read_json(folder / "out" / "summary.json");
  CHECK(summary["fits"][0]["n_points"] == 3);
  CHECK(summary["fits"][0]["n_points_at_round_off"] == 4);
  CHECK(summary["fits"][0]["steps_max"] == 256);
  CHECK(std::abs(summary["fits"][0]["exponent"].get<double>() - 4.0) < 0.1);
  CHECK(std::abs(summary["fits"][0]["energy_error_excess_at_smallest_dt"].get<double>() - 1.0) < 0.2);
  CHECK(summary["fits"][1]["n_points_at_round_off"] == 0);
  CHECK(summary["fits"][1]["round_off_dt_max"].is_null());
  CHECK(std::abs(summary["fits"][1]["energy_error_excess_at_smallest_dt"].get<double>() - 1.0) < 0.2);

  // --quiet keeps the warnings (on stderr) and drops the report.
  const auto quiet =
      run_nonsep({"run", "--quiet", "--force", "--output", (folder / "out").string(), file.string()}, folder.path());
  CHECK(quiet.out.empty());
  CHECK(quiet.err.find("nonsep: warning: mpe 4: 4 runs at the round-off floor") != std::string::npos);
}

}  // namespace test_host_study
