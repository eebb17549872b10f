// Frequency map analysis (/analysis/frequencies, observers/sampled_indicator.hpp) through the `nonsep` executable on
// paper2d: the diffusion index of a regular and a chaotic orbit (with FLI beside it), a run killed and resumed and a
// run on two threads giving an uninterrupted one-thread run's files byte for byte, a signals file changed under a
// checkpoint refused, and orbits that stop early. The frequencies against exact ones:
// tests/formula/test_formula_frequencies.cpp; NAFF itself: tests/core/test_frequency_analysis.cpp.
#include <doctest/doctest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "host_run_support.hpp"

namespace test_host_frequencies {

using namespace nonsep::host_testing;

namespace {

const std::vector<double> regular_q{0.25, 0.3}, regular_p{-1.5, 0.2};  // quasi-periodic (plugins/paper2d)
const std::vector<double> chaotic_q{-0.75, 0.3}, chaotic_p{-1.5, 0.2};

// A cell that must hold a number.
double number(const std::map<std::string, std::string>& row, const std::string& name) {
  REQUIRE(row.count(name) == 1);
  REQUIRE(!row.at(name).empty());
  return cell(row, name);
}

// An ensemble of paper2d orbits on and around the two above, MPE 4 at dt = 0.005.
json ensemble_job(std::uint64_t steps) {
  json initial = json::array();
  for (int i = 0; i < 24; ++i) initial.push_back({{"q", {-0.75 + 0.05 * i, 0.3}}, {"p", {-1.5, 0.2}}});
  return {{"model", {{"plugin", "paper2d"}}},
          {"integrator", {{"scheme", "mpe"}, {"order", 4}}},
          {"initial", initial},
          {"time", {{"dt", 0.005}, {"steps", steps}}},
          {"output", {{"every", 0}}},
          {"analysis", {{"frequencies", {{"every", 3}, {"spectra", 2}}}}}};
}

const char* const frequency_files[] = {"trajectories.csv", "frequency_spectra.csv", "frequency_signals.npy"};

}  // namespace

TEST_CASE("frequency map: the diffusion index is small on paper2d's regular orbit and large on its chaotic one") {
  // t = 400 (about 70 turns of q + i p), 16000 samples. Measured: diffusion -6.3 on the regular orbit and -1.3 on the
  // chaotic one. FLI separates the same two orbits (7.3 and 139.5: the test "MEGNO: <Y> -> 2 within 5% ... FLI").
  TemporaryFolder folder;
  const json job = {{"model", {{"plugin", "paper2d"}}},
                    {"integrator", {{"scheme", "mpe"}, {"order", 4}}},
                    {"initial", {{{"q", regular_q}, {"p", regular_p}}, {{"q", chaotic_q}, {"p", chaotic_p}}}},
                    {"time", {{"dt", 0.005}, {"steps", 80000}}},
                    {"output", {{"every", 0}}},
                    {"analysis", {{"frequencies", {{"every", 5}}}}}};
  const auto result = run_named(folder, "run", job);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto rows = table(folder / "run/trajectories.csv");
  REQUIRE(rows.size() == 2);
  MESSAGE("diffusion: regular " << rows[0].at("diffusion") << ", chaotic " << rows[1].at("diffusion"));
  CHECK(number(rows[0], "diffusion") < -5.0);
  CHECK(number(rows[1], "diffusion") > -3.0);
  // The torus's frequencies are the same in both halves to the index's precision; each is within the sampling band.
  for (const char* k : {"0", "1"}) {
    const std::string name = std::string("frequency") + k;
    CHECK(std::abs(number(rows[0], name + "_first") - number(rows[0], name + "_second")) <=
          1e-4 * std::abs(number(rows[0], name)));
    CHECK(std::abs(number(rows[0], name)) < M_PI / (5 * 0.005));
  }
  const json summary = read_json(folder / "run/summary.json");
  CHECK(summary["analysis"]["frequencies"]["samples"] == 16000);
  CHECK(summary["analysis"]["frequencies"]["analysed"] == 2);
  CHECK(summary["analysis"]["frequencies"]["spectra_file"].is_null());
  CHECK(!std::filesystem::exists(folder / "run/frequency_spectra.csv"));
}

TEST_CASE(
    "frequency map: killed and resumed, and on two threads, the files of one uninterrupted thread byte for byte") {
  TemporaryFolder folder;
  json job = ensemble_job(6000);
  job["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
  const auto reference = run_named(folder, "reference", job, {"--threads", "1"});
  INFO("stderr: " << reference.err);
  REQUIRE(reference.status == 0);
  const auto two = run_named(folder, "two", job, {"--threads", "2"});
  REQUIRE(two.status == 0);
  const auto file = write_job(folder / "job.json", job);
  const auto step = kill_after_checkpoint(file, folder / "killed", 1000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  CHECK(step < 6000);
  const auto resumed = run_nonsep(
      {"run", "--quiet", "--resume", "--output", (folder / "killed").string(), file.string()}, folder.path());
  INFO("resumed stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  for (const char* name : frequency_files) {
    CAPTURE(name);
    const std::string expected = read_text(folder / "reference" / name);
    CHECK(read_text(folder / "two" / name) == expected);
    CHECK(read_text(folder / "killed" / name) == expected);
  }
  const auto rows = table(folder / "reference/trajectories.csv");
  REQUIRE(rows.size() == 24);
  for (const auto& row : rows) CHECK(!row.at("diffusion").empty());
  CHECK(read_csv(folder / "reference/frequency_spectra.csv").size() == 1 + 24 * 2 * 2);
}

TEST_CASE("frequency map: a resume refuses a signals file that is not the one its checkpoint counted, exit 2") {
  TemporaryFolder folder;
  json job = ensemble_job(6000);
  job["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
  const auto file = write_job(folder / "job.json", job);
  kill_after_checkpoint(file, folder / "out", 1000, folder.path());
  const auto signals = folder / "out/frequency_signals.npy";
  std::string bytes = read_text(signals);
  bytes[bytes.size() / 24 / 2 + 300] ^= 1;  // a sample of trajectory 0 (the first 1/24 of the data after the header)
  std::ofstream(signals, std::ios::binary | std::ios::trunc) << bytes;
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  CHECK(resumed.status == 2);
  CHECK(resumed.err.find("frequency_signals.npy") != std::string::npos);
  CHECK(resumed.err.find("--force") != std::string::npos);
}

TEST_CASE("frequency map: a resume with other frequency settings is refused, naming the analysis") {
  TemporaryFolder folder;
  json job = ensemble_job(6000);
  job["checkpoint"] = {{"every_steps", 500}, {"every_seconds", 0}};
  const auto file = write_job(folder / "job.json", job);
  kill_after_checkpoint(file, folder / "out", 1000, folder.path());
  job["analysis"]["frequencies"]["every"] = 6;
  const auto changed = write_job(folder / "changed.json", job);
  const auto resumed = run_nonsep(
      {"run", "--quiet", "--resume", "--output", (folder / "out").string(), changed.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  CHECK(resumed.status == 2);
  CHECK(resumed.err.find("belongs to a different job: its analysis differs") != std::string::npos);
}

TEST_CASE("frequency map: the frequency columns do not depend on how many terms the spectra hold") {
  // The spectra's terms are projected together, which changes their amplitudes and can rank a later term first;
  // the columns are the strongest term found alone.
  TemporaryFolder folder;
  json few = ensemble_job(2000);
  few["initial"] = json::array({few["initial"][0], few["initial"][11], few["initial"][23]});
  json many = few;
  few["analysis"]["frequencies"]["spectra"] = 0;
  many["analysis"]["frequencies"]["spectra"] = 166;  // samples / 4
  REQUIRE(run_named(folder, "few", few).status == 0);
  REQUIRE(run_named(folder, "many", many).status == 0);
  const auto a = table(folder / "few/trajectories.csv"), b = table(folder / "many/trajectories.csv");
  REQUIRE(a.size() == b.size());
  for (std::size_t t = 0; t < a.size(); ++t)
    for (const char* column : {"frequency0", "frequency1_first", "diffusion"})
      CHECK(a[t].at(column) == b[t].at(column));
  const auto spectra = table(folder / "many/frequency_spectra.csv");
  CHECK(spectra.size() > 3 * 2 * 100);
}

TEST_CASE("frequency map: an orbit that diverges has empty cells, one stopped early by max_crossings is analysed") {
  TemporaryFolder folder;
  use_test_plugins();
  // blowup's orbits from q = 0.8 and on diverge mid-run (a non-finite sample: no analysis); paper2d's stop at their
  // 40th Poincare crossing (about t = 250), long after 32 samples.
  json diverging = blowup_job(json::array({state(0.8, 0.5), state(0.1, 0.1)}));
  diverging["time"] = {{"dt", 0.001}, {"steps", 2000}};
  diverging["output"] = {{"every", 0}};
  diverging["analysis"] = {{"frequencies", {{"every", 10}}}};
  const auto blown = run_named(folder, "blowup", diverging);
  INFO("stderr: " << blown.err);
  const auto rows = table(folder / "blowup/trajectories.csv");
  REQUIRE(rows.size() == 2);
  CHECK(rows[0].at("status") == "diverged");
  CHECK(rows[0].at("frequency0").empty());
  CHECK(rows[0].at("diffusion").empty());
  CHECK(rows[1].at("status") == "completed");
  CHECK(!rows[1].at("frequency0").empty());

  json stopped = ensemble_job(80000);
  stopped["initial"] = json::array({{{"q", regular_q}, {"p", regular_p}}});
  stopped["analysis"]["poincare"] = {{"component", "q1"}, {"value", 0.0}, {"max_crossings", 40}};
  const auto result = run_named(folder, "stopped", stopped);
  INFO("stderr: " << result.err);
  REQUIRE(result.status == 0);
  const auto stopped_rows = table(folder / "stopped/trajectories.csv");
  REQUIRE(stopped_rows.size() == 1);
  CHECK(number(stopped_rows[0], "step") < 80000);
  MESSAGE("stopped at step " << stopped_rows[0].at("step") << ", diffusion " << stopped_rows[0].at("diffusion"));
  CHECK(number(stopped_rows[0], "diffusion") < -4.0);
}

TEST_CASE("frequency map: validate says what will be sampled and how large the signals file will be") {
  TemporaryFolder folder;
  json job = ensemble_job(6000);  // 24 orbits, 2 signals, 2000 samples: 1.536 MB
  job["analysis"]["frequencies"]["spectra"] = 3;
  const auto file = write_job(folder / "job.json", job);
  const auto result = run_nonsep({"validate", file.string()}, folder.path());
  INFO("stdout: " << result.out << "stderr: " << result.err);
  REQUIRE(result.status == 0);
  CHECK(result.out.find("frequencies: 2 signals q_k + i p_k, 2000 samples every 3 steps (tau = 0.015), "
                        "frequency_signals.npy 1.5 MB, frequency_spectra.csv with 3 terms a signal") !=
        std::string::npos);
  CHECK(result.out.find("H_TTV") != std::string::npos);
  job["model"] = {{"plugin", "henon_heiles"}};
  job["integrator"] = {{"scheme", "gauss"}, {"stages", 2}};
  job["initial"] = {{"q", {0.0, 0.1}}, {"p", {0.3, 0.0}}};
  const auto given = write_job(folder / "given.json", job);
  const auto by_h = run_nonsep({"validate", given.string()}, folder.path());
  INFO("stdout: " << by_h.out);
  CHECK(by_h.out.find("H given by the model") != std::string::npos);
  CHECK(by_h.out.find("H_TTV") == std::string::npos);
}

}  // namespace test_host_frequencies
