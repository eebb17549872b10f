// The comparator schemes (tao, implicit_midpoint, gauss) through the built executable: runs and studies through the
// ensemble driver, bit for bit with the core; the family in --help, summary.json and the CSV files; the Tao copy
// distance; a Gauss trajectory whose iteration fails retiring alone with the reason; plugins without third
// derivatives refused; work_precision.csv; a Tao run killed and resumed.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/job.hpp"

namespace test_host_comparators {

using json = nlohmann::json;
using namespace nonsep::host_testing;

namespace {

constexpr double p_at_quarter = -1.5723027555148466;

json ensemble(std::initializer_list<std::pair<double, double>> states) {
  json list = json::array();
  for (const auto& [q, p] : states) list.push_back(state(q, p));
  return list;
}

std::size_t column(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t c = 0; c < header.size(); ++c)
    if (header[c] == name) return c;
  FAIL("no column " << name);
  return 0;
}

}  // namespace

TEST_CASE("tao and gauss runs: the core's numbers bit for bit, family and grad_H in summary.json") {
  TemporaryFolder folder;
  for (const json& integrator : {json{{"scheme", "tao"}, {"order", 4}, {"omega", 20}},
                                 json{{"scheme", "gauss"}, {"stages", 3}}, json{{"scheme", "implicit_midpoint"}}}) {
    const std::string scheme = integrator["scheme"];
    CAPTURE(scheme);
    // Three trajectories in blocks of one per thread and together: the driver batches and threads them.
    json job = paper1d_job(ensemble({{2.0, 0.0}, {1.0, 0.5}, {0.5, -0.3}}), {{"dt", 0.01}, {"steps", 40}}, integrator);
    job["output"]["every"] = 10;
    const json summary = run_job(folder, scheme, job);
    CHECK(summary["status"] == "completed");
    CHECK(summary["integrator"]["family"] == "comparator");
    CHECK(summary["integrator"]["scheme"] == scheme);
    CHECK(summary["evaluations"]["grad_T"] == 0);
    CHECK(summary["evaluations"]["grad_V"] == 0);
    CHECK(summary["evaluations"]["grad_H"].get<std::uint64_t>() >= 3 * 40);
    nonsep::IntegratorSpec spec{scheme};
    if (spec.scheme == "tao") spec.options = nonsep::TaoOptions{nonsep::Fraction(integrator.value("order", 2))};
    if (spec.scheme == "gauss") spec.options = nonsep::GaussOptions{integrator.value("stages", 2)};
    const double starts[3][2] = {{2.0, 0.0}, {1.0, 0.5}, {0.5, -0.3}};
    for (std::size_t k = 0; k < 3; ++k) {
      const CoreRun core = core_run(spec, starts[k][0], starts[k][1], 0.01, 40);
      const json& final_state = summary["trajectories"][k]["final"];
      CHECK(number(final_state["q"][0]) == core.state.q()[0]);
      CHECK(number(final_state["p"][0]) == core.state.p()[0]);
    }
    if (scheme == "tao") {
      const double distance = number(summary["comparator"]["max_copy_distance"]);
      CHECK(distance > 0.0);
      CHECK(distance < 1e-3);
    } else {
      CHECK_FALSE(summary.contains("comparator"));
    }
  }
  const json chin = run_job(folder, "triplet", paper1d_job(state(2.0, 0.0), {{"dt", 0.01}, {"steps", 4}}));
  CHECK(chin["integrator"]["family"] == "chin");
  CHECK(chin["evaluations"]["grad_H"] == 0);
}

TEST_CASE("gauss: a trajectory whose fixed-point iteration fails retires as failed with the reason, alone") {
  TemporaryFolder folder;
  // At (20, 0) dt |d2H/dp2| = 0.05 * 2 (1 + 400) = 40: the iteration cannot contract; at (2, 0) it is 0.5.
  json job = paper1d_job(ensemble({{2.0, 0.0}, {20.0, 0.0}, {1.5, 0.1}}), {{"dt", 0.05}, {"steps", 6}},
                         {{"scheme", "gauss"}, {"stages", 2}, {"max_iterations", 60}});
  const json summary = run_job(folder, "gauss-fails", job, 1);
  CHECK(summary["counts"]["failed"] == 1);
  CHECK(summary["counts"]["completed"] == 2);
  const json& failed = summary["trajectories"][1];
  CHECK(failed["status"] == "failed");
  CHECK(failed["final"]["step"] == 0);  // the state before the failed step: never an inaccurate step
  // The message has commas: read it from the file itself (the test's CSV reader splits quoted cells).
  const std::string message = read_text(folder / "gauss-fails" / "trajectories.csv");
  INFO("trajectories.csv: " << message);
  CHECK(message.find("fixed-point iteration failed") != std::string::npos);
  CHECK((message.find("no convergence in 60 iterations") != std::string::npos ||
         message.find("not finite") != std::string::npos));
  CHECK(summary["trajectories"][0]["status"] == "completed");
  CHECK(summary["trajectories"][2]["status"] == "completed");
  // The survivors have the numbers of a run without the failing trajectory.
  const CoreRun alone = core_run(
      [] {
        return nonsep::IntegratorSpec{"gauss", nonsep::GaussOptions{2, 60}};
      }(),
      1.5, 0.1, 0.05, 6);
  CHECK(number(summary["trajectories"][2]["final"]["q"][0]) == alone.state.q()[0]);
}

TEST_CASE("tao: a trajectory that diverges leaves the block with its copy, the others keep theirs bit for bit") {
  TemporaryFolder folder;
  // (3, 6) diverges at step 2, after the block has stepped all three once: the driver redoes the chunk step by
  // step and compacts the block and Tao's copies; the survivors must still be the core's single runs.
  json job = paper1d_job(ensemble({{2.0, 0.0}, {3.0, 6.0}, {1.5, 0.1}}), {{"dt", 0.02}, {"steps", 50}},
                         {{"scheme", "tao"}, {"order", 2}});
  job["output"]["every"] = 10;
  const json summary = run_job(folder, "tao-diverges", job, 1);
  CHECK(summary["counts"]["diverged"] == 1);
  CHECK(summary["trajectories"][1]["status"] == "diverged");
  CHECK(summary["trajectories"][1]["final"]["step"] == 1);
  const nonsep::IntegratorSpec spec{"tao", nonsep::TaoOptions{nonsep::Fraction(2)}};
  for (const std::size_t k : {0u, 2u}) {
    CAPTURE(k);
    const double q0 = k == 0 ? 2.0 : 1.5, p0 = k == 0 ? 0.0 : 0.1;
    const CoreRun core = core_run(spec, q0, p0, 0.02, 50);
    CHECK(summary["trajectories"][k]["status"] == "completed");
    CHECK(number(summary["trajectories"][k]["final"]["q"][0]) == core.state.q()[0]);
    CHECK(number(summary["trajectories"][k]["final"]["p"][0]) == core.state.p()[0]);
  }
}

TEST_CASE("comparators need Hessians and third derivatives: refused at the scheme's path, with the reason") {
  TemporaryFolder folder;
  use_test_plugins();
  for (const char* plugin : {"blowup", "blowup_gradients_only"}) {
    CAPTURE(plugin);
    json job = blowup_job(state(1.0, 0.5), json::object(), plugin);
    job["integrator"] = {{"scheme", "tao"}};
    const auto file = write_job(folder / (std::string(plugin) + ".json"), job);
    const auto result =
        run_nonsep({"run", "--quiet", "--output", (folder / plugin).string(), file.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("/integrator/scheme") != std::string::npos);
    CHECK(result.err.find(std::string(plugin) == "blowup" ? "no third derivatives" : "no Hessians") !=
          std::string::npos);
  }
}

TEST_CASE("--help names each scheme's family") {
  TemporaryFolder folder;
  const auto result = run_nonsep({"--help"}, folder.path());
  CHECK(result.out.find("triplet [family chin]") != std::string::npos);
  CHECK(result.out.find("tao [family comparator]") != std::string::npos);
  CHECK(result.out.find("gauss [family comparator]") != std::string::npos);
  CHECK(result.out.find("implicit_midpoint [family comparator]") != std::string::npos);
}

TEST_CASE("a study of Chin's schemes and comparators writes work_precision.csv with medians over the repeats") {
  TemporaryFolder folder;
  const json job = {{"model", {{"plugin", "paper1d"}}},
                    {"initial", state(2.0, 0.0)},
                    {"time", {{"t_end", quarter_period}}},
                    {"study",
                     {{"repeats", 3},
                      {"reference", {{"q", {0.0}}, {"p", {p_at_quarter}}}},
                      {"integrators",
                       {{{"scheme", "triplet"}, {"order", 2}, {"steps", {64, 128}}},
                        {{"scheme", "tao"}, {"order", 4}, {"steps", {64, 128}}},
                        {{"scheme", "gauss"}, {"stages", 2}, {"label", "gauss 4"}, {"steps", {16, 32}}}}}}}};
  const auto file = write_job(folder / "wp.json", job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "wp").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = read_csv(folder / "wp" / "work_precision.csv");
  REQUIRE(rows.size() == 7);
  const auto& h = rows[0];
  const json summary = read_json(folder / "wp" / "summary.json");
  CHECK(summary["output"]["work_precision"] == "work_precision.csv");
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto& row = rows[r];
    CAPTURE(row[0]);
    CHECK(row[column(h, "repeats")] == "3");
    CHECK(std::stod(row[column(h, "wall_seconds")]) > 0.0);
    CHECK(row[column(h, "status")] == "completed");
    const bool comparator = row[column(h, "scheme")] != "triplet";
    CHECK(row[column(h, "family")] == (comparator ? "comparator" : "chin"));
    const auto grad_h = std::stoull(row[column(h, "grad_H")]);
    CHECK(std::stoull(row[column(h, "evaluations")]) ==
          std::stoull(row[column(h, "grad_T")]) + std::stoull(row[column(h, "grad_V")]) + grad_h);
    CHECK((grad_h > 0) == comparator);
  }
  CHECK(rows[3][column(h, "options")] == "order=4 omega=20");
  CHECK(rows[5][column(h, "options")] == "stages=2 max_iterations=100");
  // Tao 4 at 128 steps against 64: about 2^4 times smaller phase error.
  const double ratio = std::stod(rows[3][column(h, "phase_error")]) / std::stod(rows[4][column(h, "phase_error")]);
  CHECK(ratio > 12.0);
  CHECK(ratio < 20.0);
}

TEST_CASE("a study's default labels name each integrator's order as summary.json reports it") {
  TemporaryFolder folder;
  const json job = {{"model", {{"plugin", "paper1d"}}},
                    {"initial", state(2.0, 0.0)},
                    {"time", {{"t_end", quarter_period}}},
                    {"study",
                     {{"steps", {16, 32}},
                      {"integrators",
                       {{{"scheme", "gauss"}, {"stages", 2}},
                        {{"scheme", "gauss"}, {"stages", 3}},
                        {{"scheme", "implicit_midpoint"}},
                        {{"scheme", "tao"}, {"order", 4}},
                        {{"scheme", "mpe"}, {"order", "8/3"}},
                        {{"scheme", "basic"}}}}}}};
  const auto file = write_job(folder / "labels.json", job);
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "labels").string(), file.string()}, folder.path());
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const json fits = read_json(folder / "labels" / "summary.json")["fits"];
  REQUIRE(fits.size() == 6);
  const std::vector<std::string> labels{"gauss 4", "gauss 6", "implicit_midpoint 2", "tao 4", "mpe 8/3", "basic"};
  for (std::size_t i = 0; i < fits.size(); ++i) {
    CHECK(fits[i]["integrator"] == labels[i]);
    if (i + 1 < fits.size())
      CHECK(fits[i]["integrator"] == fits[i]["scheme"].get<std::string>() + " " + fits[i]["order"].get<std::string>());
  }
}

TEST_CASE("a study's reference_run: its end state is the reference of the phase errors, as a given reference") {
  TemporaryFolder folder;
  const nonsep::IntegratorSpec reference_spec{"gauss", nonsep::GaussOptions{3}};
  const CoreRun reference = core_run(reference_spec, 2.0, 0.0, quarter_period / 256, 256);
  json job = {{"model", {{"plugin", "paper1d"}}},
              {"initial", state(2.0, 0.0)},
              {"time", {{"t_end", quarter_period}}},
              {"study",
               {{"reference_run", {{"scheme", "gauss"}, {"stages", 3}, {"steps", {256}}}},
                {"integrators", {{{"scheme", "tao"}, {"order", 2}, {"steps", {32, 64}}}}}}}};
  const auto run_study = [&](const std::string& name) {
    const auto file = write_job(folder / (name + ".json"), job);
    const auto result =
        run_nonsep({"run", "--quiet", "--output", (folder / name).string(), file.string()}, folder.path());
    INFO("stderr: " << result.err);
    REQUIRE(result.status == 0);
  };
  run_study("with-run");
  const json summary = read_json(folder / "with-run" / "summary.json");
  CHECK(summary["study"]["reference"]["p"][0].get<double>() == reference.state.p()[0]);
  CHECK(summary["study"]["reference_from"]["scheme"] == "gauss");
  CHECK(summary["study"]["reference_from"]["steps"] == 256);
  // The same study with that end state written as /study/reference gives the same phase errors, bit for bit.
  job["study"].erase("reference_run");
  job["study"]["reference"] = {{"q", {reference.state.q()[0]}}, {"p", {reference.state.p()[0]}}};
  run_study("given");
  const auto a = read_csv(folder / "with-run" / "work_precision.csv"),
             b = read_csv(folder / "given" / "work_precision.csv");
  REQUIRE(a.size() == 3);
  REQUIRE(b.size() == 3);
  const std::size_t phase = column(a[0], "phase_error");
  CHECK(a[1][phase] == b[1][phase]);
  CHECK(a[2][phase] == b[2][phase]);
  CHECK(std::stod(a[1][phase]) > 1e-6);
}

TEST_CASE("a Tao run killed and resumed continues its copies: the files and the copy distance bit for bit") {
  json initial = json::array();
  for (int k = 0; k < 300; ++k) initial.push_back(state(0.5 + 0.005 * k, 0.1));
  json job = paper1d_job(initial, {{"dt", 0.001}, {"steps", 60000}}, {{"scheme", "tao"}, {"order", 2}});
  job["output"]["every"] = 1000;
  job["checkpoint"] = {{"every_steps", 1000}, {"every_seconds", 0}};
  TemporaryFolder reference;
  const json uninterrupted = run_job(reference, "out", job);

  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", job);
  const auto step = kill_after_checkpoint(file, folder / "out", 20000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  REQUIRE(step < 60000);
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  for (const char* name : {"trajectory.csv", "trajectories.csv"}) {
    CAPTURE(name);
    CHECK(read_text(folder / "out" / name) == read_text(reference / "out" / name));
  }
  const json summary = read_run(folder / "out");
  CHECK(summary["comparator"]["max_copy_distance"] == uninterrupted["comparator"]["max_copy_distance"]);
  // The resumed process evaluates one grad H per trajectory to start (the gradient the killed one had cached).
  CHECK(summary["evaluations"]["grad_H"].get<std::uint64_t>() ==
        uninterrupted["evaluations"]["grad_H"].get<std::uint64_t>() + 300);
}

TEST_CASE("every option of every catalogue entry is in the checkpoint's fingerprint, and a changed one is named") {
  use_test_plugins();
  TemporaryFolder folder;
  for (const nonsep::Scheme& scheme : nonsep::scheme_catalogue()) {
    CAPTURE(scheme.name);
    const auto file = write_job(folder / (scheme.name + ".json"),
                                paper1d_job(state(2.0, 0.0), {{"dt", 0.01}, {"steps", 4}}, {{"scheme", scheme.name}}));
    nonsep::host::LoadedJob loaded = nonsep::host::load_job(file);
    const std::string fingerprint = nonsep::host::job_fingerprint(loaded);
    for (const nonsep::ParameterDescription& option : scheme.parameters) {
      CAPTURE(option.name);
      nonsep::host::LoadedJob changed = loaded;
      auto& spec = std::get<nonsep::host::SingleRun>(changed.job.plan).integrator;
      const nonsep::OptionValue value = nonsep::option_value(spec, option);
      if (std::holds_alternative<nonsep::Fraction>(value))
        nonsep::set_option(spec, option, nonsep::Fraction(99, 7));
      else
        nonsep::set_option(spec, option, std::get<double>(value) * 2 + 1);
      CHECK(nonsep::host::fingerprint_difference(fingerprint, nonsep::host::job_fingerprint(changed)) ==
            "integrator." + option.name);
    }
  }
}

TEST_CASE(
    "a comparator resumed with another option is refused with exit 2 naming it (Tao's omega, Gauss's iterations)") {
  const std::pair<json, json> changes[] = {
      {{{"scheme", "tao"}, {"order", 2}, {"omega", 20}}, {{"scheme", "tao"}, {"order", 2}, {"omega", 5}}},
      {{{"scheme", "gauss"}, {"max_iterations", 100}}, {{"scheme", "gauss"}, {"max_iterations", 3}}}};
  for (const auto& [before, after] : changes) {
    const json first = before;  // clang 14 cannot capture a structured binding
    CAPTURE(first);
    json initial = json::array();
    for (int k = 0; k < 50; ++k) initial.push_back(state(0.5 + 0.005 * k, 0.1));
    json job = paper1d_job(initial, {{"dt", 0.001}, {"steps", 1000000}}, before);
    job["checkpoint"] = {{"every_steps", 100}, {"every_seconds", 0}};
    TemporaryFolder folder;
    const auto file = write_job(folder / "job.json", job);
    kill_after_checkpoint(file, folder / "out", 100, folder.path());
    const std::string checkpoint = read_text(folder / "out" / "checkpoint.json");
    job["integrator"] = after;
    write_job(file, job);
    const auto refused =
        run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
    INFO("stderr: " << refused.err);
    CHECK(refused.status == 2);
    const std::string option = before.contains("omega") ? "integrator.omega" : "integrator.max_iterations";
    CHECK(refused.err.find("its " + option + " differs") != std::string::npos);
    CHECK(read_text(folder / "out" / "checkpoint.json") == checkpoint);
  }
}

}  // namespace test_host_comparators
