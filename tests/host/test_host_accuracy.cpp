// Accuracy on request: studies report the largest |dH/H0| over each run (checked against the core stepping the same
// model with H at every step), /analysis/error_estimate (against exact solutions and a Gauss 6 reference at a tiny
// step; a chaotic orbit flagged after its runs separate) and scheme "auto" (its choice meets the tolerance against
// exact solutions; its bad inputs).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core.hpp"
#include "nonsep/host/study/convergence_study.hpp"
#include "nonsep/reference/mathews_lakshmanan_exact.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "paper1d/paper1d.hpp"

namespace test_host_accuracy {

using json = nlohmann::json;
using namespace nonsep::host_testing;

namespace {

constexpr double quarter_period = 0.3863765573361232;
constexpr double p_at_quarter = -1.5723027555148466;
const nonsep::reference::MathewsLakshmanan oscillator{0.5, 1.0};

// Empty cells are NaN.
double number(const std::map<std::string, std::string>& row, const std::string& name) {
  const std::string& text = row.at(name);
  return text.empty() ? std::nan("") : std::stod(text);
}

struct Ran {
  int status;
  std::string out, err;
  std::filesystem::path folder;
};
Ran run_accuracy_job(const TemporaryFolder& folder, const std::string& name, const json& job,
                     std::vector<std::string> extra = {"--quiet"}) {
  const auto file = write_job(folder / (name + ".json"), job);
  std::vector<std::string> args{"run"};
  args.insert(args.end(), extra.begin(), extra.end());
  args.insert(args.end(), {"--output", (folder / name).string(), file.string()});
  const auto result = run_nonsep(args, folder.path());
  return {result.status, result.out, result.err, folder / name};
}

json run_of(json model, json integrator, json initial, double dt, double t_end, std::uint64_t every) {
  return {{"model", std::move(model)},
          {"integrator", std::move(integrator)},
          {"initial", std::move(initial)},
          {"time", {{"dt", dt}, {"t_end", t_end}}},
          {"output", {{"every", every}}}};
}

double distance(double q0, double p0, double q1, double p1) { return std::hypot(q0 - q1, p0 - p1); }

}  // namespace

TEST_CASE("a study reports the largest |dH/H0| over each run, which the core finds stepping with H at every step") {
  const TemporaryFolder folder;
  // A full period of paper1d: at t_end the energy error of a symplectic scheme is back near its start, its
  // largest value was in between.
  const double t_end = 4 * quarter_period;
  const json job = {{"model", {{"plugin", "paper1d"}}},
                    {"initial", {{"q", {2.0}}, {"p", {0.0}}}},
                    {"time", {{"t_end", t_end}}},
                    {"study", {{"integrators", {{{"scheme", "triplet"}, {"order", "8/3"}, {"steps", {256, 512}}}}}}}};
  const auto ran = run_accuracy_job(folder, "study", job);
  REQUIRE(ran.status == 0);
  const auto rows = table(ran.folder / "work_precision.csv");
  REQUIRE(rows.size() == 2);
  const nonsep::sdk::ModelAdapter<::Paper1D> model;
  nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
  const double q0[] = {2.0}, p0[] = {0.0};
  for (const auto& row : rows) {
    const auto steps = std::stoull(row.at("steps"));
    nonsep::Integrator integrator({"triplet", nonsep::ChinOptions{nonsep::Fraction(8, 3)}});
    auto x = nonsep::PhaseSpaceBatch::single(q0, p0);
    const double h0 = energy.evaluate_one(model, x);
    double largest = 0.0, at_end = 0.0;
    for (std::uint64_t k = 0; k < steps; ++k) {
      integrator.step(model, x, t_end / static_cast<double>(steps));
      at_end = (energy.evaluate_one(model, x) - h0) / h0;
      largest = std::max(largest, std::abs(at_end));
    }
    CAPTURE(steps);
    CHECK(number(row, "max_abs_relative_energy_error") == doctest::Approx(largest).epsilon(1e-9));
    CHECK(number(row, "relative_energy_error") == doctest::Approx(at_end).epsilon(1e-9));
    CHECK(largest > 2 * std::abs(at_end));  // the case that made the maximum necessary
  }
  const json summary = read_json(ran.folder / "summary.json");
  const auto& fit = summary["fits"][0];
  const double coarse = number(rows[0], "max_abs_relative_energy_error"),
               fine = number(rows[1], "max_abs_relative_energy_error");
  CHECK(fit["exponent"].get<double>() == doctest::Approx(std::log(coarse / fine) / std::log(2.0)).epsilon(1e-9));
  CHECK(fit["energy_error_rises"].is_null());
}

TEST_CASE("a fit over a ladder whose largest energy error rises as dt shrinks says so") {
  nonsep::host::StudyIntegrator integrator;
  integrator.label = "basic";
  integrator.spec.scheme = "basic";
  const auto description = nonsep::Integrator(integrator.spec).describe();
  std::vector<nonsep::host::StudyRun> runs;
  for (const auto& [steps, error] :
       std::vector<std::pair<std::uint64_t, double>>{{100, 1e-2}, {200, 2e-2}, {400, 4e-3}}) {
    nonsep::host::StudyRun run;
    run.steps = steps;
    run.dt = 1.0 / static_cast<double>(steps);
    run.relative_energy_error = -error / 2;
    run.max_abs_relative_energy_error = error;
    runs.push_back(run);
  }
  const auto fit = nonsep::host::fit_study(integrator, description, runs, false);
  REQUIRE(fit.energy_error_rises);
  CHECK(fit.energy_error_rises->steps_coarse == 100);
  CHECK(fit.energy_error_rises->steps_fine == 200);
  CHECK(fit.energy_error_rises->error_fine == 2e-2);
  runs[1].max_abs_relative_energy_error = 5e-3;
  CHECK_FALSE(nonsep::host::fit_study(integrator, description, runs, false).energy_error_rises);
}

TEST_CASE("the error estimate is within a factor 3 of the error against exact solutions") {
  const TemporaryFolder folder;
  SUBCASE("paper1d at its exact quarter period") {
    for (const json& integrator : {json{{"scheme", "triplet"}, {"order", "2"}}, json{{"scheme", "mpe"}, {"order", "4"}},
                                   json{{"scheme", "gauss"}, {"stages", 3}}}) {
      json job = run_of({{"plugin", "paper1d"}}, integrator, {{"q", {2.0}}, {"p", {0.0}}}, quarter_period / 64,
                        quarter_period, 0);
      job["analysis"] = {{"error_estimate", true}};
      const auto ran = run_accuracy_job(folder, "paper1d", job, {"--quiet", "--force"});
      REQUIRE(ran.status == 0);
      const auto row = table(ran.folder / "trajectories.csv").at(0);
      const double actual = distance(number(row, "q0"), number(row, "p0"), 0.0, p_at_quarter);
      CAPTURE(integrator.dump());
      CAPTURE(actual);
      CHECK(row.at("error_estimate") == "within_horizon");
      CHECK(number(row, "error_estimate_t") == quarter_period);
      CHECK(number(row, "estimated_phase_error") / actual == doctest::Approx(1.0).epsilon(2.0 / 3.0));
      CHECK(number(row, "estimated_phase_error") <= 3 * actual);
      CHECK(number(row, "estimated_phase_error") >= actual / 3);
      // The energy error is known exactly; its estimate agrees with it where the estimate holds.
      const double energy = number(row, "relative_energy_error");
      CHECK(std::abs(number(row, "estimated_relative_energy_error")) <= 3 * std::abs(energy));
      CHECK(std::abs(number(row, "estimated_relative_energy_error")) >= std::abs(energy) / 3);
    }
  }
  SUBCASE("mathews_lakshmanan over three periods, at every sample") {
    const double amplitude = 1.5, period = oscillator.period(amplitude);
    json job = run_of({{"plugin", "mathews_lakshmanan"}, {"parameters", {{"lambda", 0.5}, {"alpha", 1.0}}}},
                      {{"scheme", "triplet"}, {"order", "8/3"}}, {{"q", {amplitude}}, {"p", {0.0}}}, period / 1024,
                      3 * period, 128);
    job["analysis"] = {{"error_estimate", true}};
    const auto ran = run_accuracy_job(folder, "ml", job);
    REQUIRE(ran.status == 0);
    const auto rows = table(ran.folder / "error_estimate.csv");
    const auto samples = table(ran.folder / "trajectory.csv");
    REQUIRE(rows.size() == 24);
    std::size_t checked = 0;
    for (const auto& row : rows) {
      const auto sample =
          std::find_if(samples.begin(), samples.end(), [&](const auto& s) { return s.at("step") == row.at("step"); });
      REQUIRE(sample != samples.end());
      const double t = number(row, "t");
      const auto exact = oscillator.at(amplitude, std::acos(-1.0) / 2, t);
      const double actual = distance(number(*sample, "q0"), number(*sample, "p0"), exact.q, exact.p);
      CAPTURE(t);
      CHECK(row.at("separated") == "false");
      CHECK(number(row, "estimated_phase_error") <= 3 * actual);
      CHECK(number(row, "estimated_phase_error") >= actual / 3);
      ++checked;
    }
    CHECK(checked == 24);
  }
}

TEST_CASE("the error estimate on paper2d: a regular orbit against Gauss 6 at a tiny step, a chaotic one flagged") {
  const TemporaryFolder folder;
  const auto end_of = [&](const std::string& name, const json& job) {
    const auto ran = run_accuracy_job(folder, name, job);
    REQUIRE(ran.status == 0);
    return table(ran.folder / "trajectories.csv").at(0);
  };
  const auto actual_against = [](const auto& row, const auto& reference) {
    double sum = 0.0;
    for (const char* c : {"q0", "q1", "p0", "p1"}) sum += std::pow(number(row, c) - number(reference, c), 2);
    return std::sqrt(sum);
  };
  const json model = {{"plugin", "paper2d"}};
  SUBCASE("regular: q = (0, 0), p = (0.5, 2) to t = 2") {
    const json initial = {{"q", {0.0, 0.0}}, {"p", {0.5, 2.0}}};
    const auto reference =
        end_of("reference", run_of(model, {{"scheme", "gauss"}, {"stages", 3}}, initial, 2.0 / 4096, 2.0, 0));
    // Triplet 2's error constant is large here: at 2048 steps its error is 0.28, beyond the horizon.
    for (const auto& integrator_and_steps : {std::pair{json{{"scheme", "mpe"}, {"order", "4"}}, 256},
                                             std::pair{json{{"scheme", "triplet"}, {"order", "2"}}, 8192}}) {
      const json& integrator = integrator_and_steps.first;  // not a structured binding: CAPTURE's lambda takes it
      const int steps = integrator_and_steps.second;
      json job = run_of(model, integrator, initial, 2.0 / steps, 2.0, 0);
      job["analysis"] = {{"error_estimate", true}};
      const auto row = end_of("regular-" + integrator["scheme"].get<std::string>(), job);
      const double actual = actual_against(row, reference);
      CAPTURE(integrator.dump());
      CAPTURE(actual);
      CHECK(row.at("error_estimate") == "within_horizon");
      CHECK(number(row, "estimated_phase_error") <= 3 * actual);
      CHECK(number(row, "estimated_phase_error") >= actual / 3);
    }
  }
  SUBCASE("chaotic: q = (0.5, 0), p = (0, 2.5) to t = 40") {
    json job =
        run_of(model, {{"scheme", "gauss"}, {"stages", 3}}, {{"q", {0.5, 0.0}}, {"p", {0.0, 2.5}}}, 0.01, 40.0, 0);
    job["analysis"] = {{"error_estimate", true}};
    const auto ran = run_accuracy_job(folder, "chaotic", job);
    REQUIRE(ran.status == 0);
    const auto row = table(ran.folder / "trajectories.csv").at(0);
    CHECK(row.at("error_estimate") == "separated");
    const double horizon = number(row, "error_estimate_horizon");
    CHECK(horizon > 0.0);
    CHECK(horizon < 40.0);
    const json summary = read_json(ran.folder / "summary.json");
    CHECK(summary["analysis"]["error_estimate"]["separated"] == 1);
    CHECK(summary["analysis"]["error_estimate"]["earliest_horizon"].get<double>() == horizon);
    // Before the horizon no comparison is flagged, from it on every one is.
    for (const auto& estimate : table(ran.folder / "error_estimate.csv"))
      CHECK((estimate.at("separated") == "true") == (number(estimate, "t") >= horizon));
  }
}

TEST_CASE("scheme auto meets its tolerance against the exact solution and records its choice") {
  const TemporaryFolder folder;
  SUBCASE("paper1d, phase, 1e-8") {
    const json job = run_of({{"plugin", "paper1d"}}, {{"scheme", "auto"}, {"tolerance", 1e-8}},
                            {{"q", {2.0}}, {"p", {0.0}}}, quarter_period, quarter_period, 1);
    const auto ran = run_accuracy_job(folder, "paper1d", job, {});
    REQUIRE(ran.status == 0);
    CHECK(ran.out.find("auto: ") != std::string::npos);
    const auto row = table(ran.folder / "trajectories.csv").at(0);
    CHECK(distance(number(row, "q0"), number(row, "p0"), 0.0, p_at_quarter) <= 1e-8);
    const json summary = read_json(ran.folder / "summary.json");
    const json& choice = summary["scheme_choice"];
    CHECK(choice["tolerance"] == 1e-8);
    CHECK(choice["candidates"].size() == 7);
    CHECK(choice["estimated_error"].get<double>() <= 1e-8);
    CHECK(choice["tolerance_met"] == true);
    CHECK(choice["pilot_cost"]["state_steps"].get<std::uint64_t>() > 0);
    CHECK(summary["integrator"]["scheme"] ==
          choice["chosen"].get<std::string>().substr(0, choice["chosen"].get<std::string>().find(' ')));
    // The output grid of time.dt is kept: the samples are at step 0 and t_end.
    CHECK(table(ran.folder / "trajectory.csv").size() == 2);
  }
  SUBCASE("mathews_lakshmanan, energy, 1e-7, H at every step") {
    const double period = oscillator.period(1.5);
    json job =
        run_of({{"plugin", "mathews_lakshmanan"}}, {{"scheme", "auto"}, {"tolerance", 1e-7}, {"measure", "energy"}},
               {{"q", {1.5}}, {"p", {0.0}}}, period / 4, period / 4, 0);
    job["output"]["energy_every"] = 1;
    const auto ran = run_accuracy_job(folder, "ml", job);
    REQUIRE(ran.status == 0);
    const auto row = table(ran.folder / "trajectories.csv").at(0);
    CHECK(number(row, "max_abs_relative_energy_error") <= 1e-7);
    CHECK(read_json(ran.folder / "summary.json")["scheme_choice"]["measured_error"].get<double>() ==
          number(row, "max_abs_relative_energy_error"));
  }
  SUBCASE("tangent vectors keep the schemes with a tangent map: every one, with a plugin that has hvp_H") {
    json job = run_of({{"plugin", "paper2d"}}, {{"scheme", "auto"}, {"tolerance", 1e-4}},
                      {{"q", {0.0, 0.0}}, {"p", {0.5, 2.0}}}, 0.5, 1.0, 0);
    job["analysis"] = {{"megno", true}};
    const auto ran = run_accuracy_job(folder, "megno", job);
    REQUIRE(ran.status == 0);
    const json summary = read_json(ran.folder / "summary.json");  // kept: the loop below reads into it
    bool gauss = false;
    for (const auto& candidate : summary["scheme_choice"]["candidates"])
      gauss = gauss || candidate["scheme"] == "gauss";
    CHECK(gauss);
  }
}

TEST_CASE("scheme auto on an ensemble: the largest error of every state meets the tolerance, within three decades") {
  const TemporaryFolder folder;
  // 64 paper1d orbits, q0 from 0.2 to 2 (p0 = 0), to t = 10, against Gauss 16 at 400 steps (its error there is below
  // 1e-13). The error grows steeply with the amplitude: at 64 steps of Gauss 16 the last orbits are 20 times the
  // rest's worst. Pilots that left out the last state chose 64 steps and missed the tolerance (1.9e-8); a prediction
  // started from the round-off bound of the finest pilot chose 143 steps and overshot it by five decades (1.1e-13).
  const json initial = {{"grid", {{"q", {{{"from", 0.2}, {"to", 2.0}, {"count", 64}}}}, {"p", {0.0}}}}};
  const json model = {{"plugin", "paper1d"}};
  const auto reference = run_accuracy_job(
      folder, "reference", run_of(model, {{"scheme", "gauss"}, {"stages", 8}}, initial, 10.0 / 400, 10.0, 0));
  REQUIRE(reference.status == 0);
  const auto ran = run_accuracy_job(folder, "auto",
                                    run_of(model, {{"scheme", "auto"}, {"tolerance", 1e-8}}, initial, 10.0, 10.0, 0));
  REQUIRE(ran.status == 0);
  const auto exact = table(reference.folder / "trajectories.csv"), rows = table(ran.folder / "trajectories.csv");
  REQUIRE(rows.size() == 64);
  double largest = 0.0;
  for (std::size_t k = 0; k < rows.size(); ++k)
    largest = std::max(largest, distance(number(rows[k], "q0"), number(rows[k], "p0"), number(exact[k], "q0"),
                                         number(exact[k], "p0")));
  CAPTURE(largest);
  CHECK(largest <= 1e-8);
  CHECK(largest >= 1e-11);
}

TEST_CASE("scheme auto: a phase error at the round-off the orbit amplifies is measured as round-off, not as an error") {
  const TemporaryFolder folder;
  // paper2d's regular orbit q = (0, 0), p = (0.5, 2) to t = 100: Gauss 16 does not converge at 1024 steps, and from
  // 2048 steps on its runs differ by 1e-12 to 4e-12, the round-off of steps that this orbit amplifies (a start one
  // ulp away ends as far apart). The fixed bound (1e-13 of the state's length) took that for an error that does not
  // fall with the order, left Gauss 16 out and chose Gauss 8 at 14667 steps.
  const json model = {{"plugin", "paper2d"}}, initial = {{"q", {0.0, 0.0}}, {"p", {0.5, 2.0}}};
  const auto reference = run_accuracy_job(
      folder, "reference", run_of(model, {{"scheme", "gauss"}, {"stages", 8}}, initial, 100.0 / 16384, 100.0, 0));
  REQUIRE(reference.status == 0);
  const auto ran = run_accuracy_job(
      folder, "auto", run_of(model, {{"scheme", "auto"}, {"tolerance", 1e-10}}, initial, 100.0, 100.0, 0));
  REQUIRE(ran.status == 0);
  const json choice = read_json(ran.folder / "summary.json")["scheme_choice"];
  CHECK(choice["chosen"] == "gauss 16");
  const json& gauss16 = choice["candidates"].at(0);
  REQUIRE(gauss16["label"] == "gauss 16");
  CHECK(gauss16["round_off"].get<double>() > 1e-12);
  CHECK(gauss16["predicted_error"].get<double>() <= 1e-10 / 3);
  const auto exact = table(reference.folder / "trajectories.csv").at(0),
             row = table(ran.folder / "trajectories.csv").at(0);
  double squares = 0.0;
  for (const char* column : {"q0", "q1", "p0", "p1"})
    squares += std::pow(number(row, column) - number(exact, column), 2);
  CAPTURE(std::sqrt(squares));
  CHECK(std::sqrt(squares) <= 1e-10);
  // Below that round-off no step meets a tolerance, and the prediction does not claim it: the run warns.
  const auto below = run_accuracy_job(
      folder, "below", run_of(model, {{"scheme", "auto"}, {"tolerance", 1e-12}}, initial, 100.0, 100.0, 0));
  REQUIRE(below.status == 0);
  const json below_choice = read_json(below.folder / "summary.json")["scheme_choice"];
  CHECK(below_choice["estimated_error"].get<double>() >= gauss16["round_off"].get<double>());
  CHECK(below_choice["tolerance_met"] == false);
  CHECK(below.err.find("warning: scheme auto did not meet the tolerance 1e-12") != std::string::npos);
  CHECK(below.err.find("which no smaller step reduces") != std::string::npos);
  CHECK(below_choice["amplified_round_off"].get<double>() >= gauss16["round_off"].get<double>());
  // Steps smaller than those that reach the round-off gain nothing: the same step as for 1e-10.
  CHECK(below_choice["subdivision"] == choice["subdivision"]);
}

TEST_CASE("scheme auto: a phase tolerance on a chaotic orbit is not promised, the step is chosen by the energy") {
  const TemporaryFolder folder;
  // paper2d at coupling 0.2 (docs/dynamics.md): at t = 100 the pilots reach their asymptotic range only to t_end / 8,
  // and a polynomial extrapolation from there predicted 3e-7 where the chaotic orbit's phase error is of order 1.
  const auto run_orbit = [&](const std::string& name, double q0) {
    json job = run_of({{"plugin", "paper2d"}}, {{"scheme", "auto"}, {"tolerance", 1e-6}},
                      {{"q", {q0, 0.3}}, {"p", {-1.5, 0.2}}}, 100.0, 100.0, 0);
    job["output"]["energy_every"] = 1;
    return run_accuracy_job(folder, name, job, {});
  };
  SUBCASE("chaotic: q = (-0.75, 0.3), p = (-1.5, 0.2)") {
    const auto ran = run_orbit("chaotic", -0.75);
    REQUIRE(ran.status == 0);
    CHECK(ran.err.find("phase error grows exponentially") != std::string::npos);
    CHECK(ran.err.find("is not promised") != std::string::npos);
    CHECK(ran.err.find("error_estimate") != std::string::npos);
    CHECK(ran.out.find("chosen by the energy") != std::string::npos);
    const json choice = read_json(ran.folder / "summary.json")["scheme_choice"];
    CHECK(choice["measure"] == "phase");
    CHECK(choice["phase_error_growth"] == "exponential");
    CHECK(choice["chosen_by"] == "energy");
    CHECK(choice["estimated_error"].is_null());
    CHECK(choice["estimated_error_meets_tolerance"].is_null());
    CHECK(choice["tolerance_met"].is_null());
    CHECK(choice["estimated_energy_error"].get<double>() <= 1e-6);
    bool exponential = false;
    for (const auto& candidate : choice["phase_candidates"])
      exponential = exponential || (candidate["envelope_growth_exponent"].is_number() &&
                                    candidate["envelope_growth_exponent"].get<double>() > 3.0);
    CHECK(exponential);
    // The first candidate is piloted before any time bound exists: it finds the growth by itself (when its finest
    // pilots agree to round-off by t_p / 2, on a coarser pair), whichever others the bound leaves out.
    const json& first = choice["phase_candidates"].at(0);
    CHECK(first["excluded"].is_null());
    CHECK((first["envelope_growth_exponent"].is_number() && first["envelope_growth_exponent"].get<double>() > 3.0));
    // What was chosen by holds: the run's largest |dH/H0| with H at every step.
    CHECK(number(table(ran.folder / "trajectories.csv").at(0), "max_abs_relative_energy_error") <= 1e-6);
  }
  SUBCASE("regular: q = (0.25, 0.3), p = (-1.5, 0.2)") {
    const auto ran = run_orbit("regular", 0.25);
    REQUIRE(ran.status == 0);
    CHECK(ran.err.find("exponentially") == std::string::npos);
    const json choice = read_json(ran.folder / "summary.json")["scheme_choice"];
    CHECK(choice["phase_error_growth"] == "polynomial");
    CHECK(choice["chosen_by"] == "phase");
    CHECK(choice["phase_candidates"].is_null());
    CHECK(choice["estimated_error"].get<double>() <= 1e-6);
    CHECK(choice["tolerance_met"] == true);
    for (const auto& candidate : choice["candidates"])
      if (candidate["envelope_growth_exponent"].is_number())
        CHECK(candidate["envelope_growth_exponent"].get<double>() <= 3.0);
  }
}

TEST_CASE("scheme auto with a sweep meets its tolerance on every set, whose steps differ, against the exact solution") {
  const TemporaryFolder folder;
  // alpha sets the frequency: alpha = 3 or 20 needs a much smaller step than alpha = 1, whichever set comes first.
  for (const std::vector<double>& alphas : {std::vector<double>{1.0, 3.0}, std::vector<double>{1.0, 20.0}}) {
    CAPTURE(alphas[1]);
    const json job = run_of({{"plugin", "mathews_lakshmanan"}, {"parameters", {{"alpha", alphas}}}},
                            {{"scheme", "auto"}, {"tolerance", 1e-8}}, {{"q", {1.5}}, {"p", {0.0}}}, 1.0, 10.0, 0);
    const auto ran = run_accuracy_job(folder, "sweep-" + std::to_string(static_cast<int>(alphas[1])), job);
    CHECK(ran.status == 0);
    const auto rows = table(ran.folder / "trajectories.csv");
    REQUIRE(rows.size() == alphas.size());
    for (std::size_t set = 0; set < alphas.size(); ++set) {
      CAPTURE(set);
      const nonsep::reference::MathewsLakshmanan exact{0.5, alphas[set]};
      const auto end = exact.at(1.5, std::acos(-1.0) / 2, 10.0);
      CHECK(rows[set].at("status") == "completed");
      CHECK(distance(number(rows[set], "q0"), number(rows[set], "p0"), end.q, end.p) <= 1e-8);
    }
    CHECK(read_json(ran.folder / "summary.json")["scheme_choice"]["pilot_states"] == 2);
  }
}

TEST_CASE("scheme auto: validate says what would be tried, and bad tolerances and measures are refused") {
  const TemporaryFolder folder;
  json job = run_of({{"plugin", "paper1d"}}, {{"scheme", "auto"}, {"tolerance", 1e-6}}, {{"q", {2.0}}, {"p", {0.0}}},
                    0.1, 1.0, 1);
  const auto file = write_job(folder / "auto.json", job);
  const auto valid = run_nonsep({"validate", file.string()}, folder.path());
  CHECK(valid.status == 0);
  CHECK(valid.out.find("scheme auto: tolerance 1e-06") != std::string::npos);
  CHECK(valid.out.find("would try gauss 16, gauss 8, gauss 6, gauss 4, mpe 4, triplet 8/3, triplet 2") !=
        std::string::npos);
  for (const json& bad : {json{{"scheme", "auto"}}, json{{"scheme", "auto"}, {"tolerance", 0.5}},
                          json{{"scheme", "auto"}, {"tolerance", 1e-6}, {"measure", "both"}},
                          json{{"scheme", "auto"}, {"tolerance", 1e-6}, {"order", "2"}}}) {
    job["integrator"] = bad;
    const auto result = run_nonsep({"validate", write_job(folder / "bad.json", job).string()}, folder.path());
    CAPTURE(bad.dump());
    CHECK(result.status == 2);
    CHECK(result.err.find("/integrator/") != std::string::npos);
  }
  job["study"] = {{"integrators", {{{"scheme", "auto"}, {"tolerance", 1e-6}, {"steps", {4}}}}}};
  job.erase("integrator");
  job["time"] = {{"t_end", 1.0}};
  job.erase("output");
  const auto study = run_nonsep({"validate", write_job(folder / "study.json", job).string()}, folder.path());
  CHECK(study.status == 2);
  CHECK(study.err.find("/study/integrators/0/scheme") != std::string::npos);
}

}  // namespace test_host_accuracy
