// The `nonsep` executable's ensemble driver: results that do not depend on the number of threads, on where chunks
// end, on stepping in chunks or sample by sample, nor on replaying a chunk; the --threads option.
#include <doctest/doctest.h>

#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"

namespace test_host_threads {

using nlohmann::json;
using namespace nonsep::host_testing;

TEST_CASE(
    "threads: 1, 2 and 3 threads write byte-identical trajectory.csv, trajectories.csv and summary.json (but "
    "wall_seconds)") {
  TemporaryFolder folder;
  use_test_plugins();
  // 600 trajectories: ten blocks of 64 (run_block_size_for), whatever the threads. A diverging state in the second
  // block and, in the second job, a failing state in the ninth make blocks replay their chunk step by step.
  json diverging = json::array(), failing = json::array(), completing = json::array();
  for (int i = 0; i < 600; ++i) {
    const double q = 0.5 + 0.001 * i;
    diverging.push_back(i == 100 ? state(1e103, 1.0) : state(q, 0.25));
    failing.push_back(i == 550 ? state(5.0, 0.0) : state(q, 0.25));
    completing.push_back(state(q, 0.25));
  }
  for (const auto& [name, job, expected] :
       {std::tuple{"diverging", blowup_job(diverging), 1},
        std::tuple{"failing", blowup_job(failing, {{"fail_above", 3.0}}), 1},
        std::tuple{"paper1d", paper1d_job(completing, {{"dt", 0.002}, {"steps", 30}}), 0}}) {
    const std::string job_name = name;
    CAPTURE(job_name);
    const auto file = write_job(folder / (std::string(name) + ".json"), job);
    std::vector<std::string> csv, table;
    std::vector<json> summaries;
    for (const char* threads : {"1", "2", "3"}) {
      const auto out = folder / (std::string(name) + "-" + threads);
      const auto result =
          run_nonsep({"run", "--quiet", "--threads", threads, "--output", out.string(), file.string()}, folder.path());
      CHECK(result.status == expected);
      csv.push_back(read_text(out / "trajectory.csv"));
      table.push_back(read_text(out / "trajectories.csv"));
      summaries.push_back(comparable(read_json(out / "summary.json")));
    }
    CHECK(read_csv(folder / (std::string(name) + "-1") / "trajectories.csv").size() == 601);
    CHECK(table[1] == table[0]);
    CHECK(table[2] == table[0]);
    CHECK(csv[0].size() > 10000);
    CHECK(csv[1] == csv[0]);
    CHECK(csv[2] == csv[0]);
    CHECK(summaries[1] == summaries[0]);
    CHECK(summaries[2] == summaries[0]);
  }
}

namespace {

// Every file a run of `job` writes, read back (summary.json without its wall time and folder), with chunks of
// `chunk_seconds` on two threads.
std::map<std::string, std::string> run_in_chunks(const TemporaryFolder& folder, const std::string& name,
                                                 const json& job, double chunk_seconds) {
  const auto loaded = nonsep::host::load_job(write_job(folder / (name + ".json"), job));
  nonsep::host::RunOptions options;
  options.threads = 2;
  options.chunk_seconds = chunk_seconds;
  options.output_directory = folder / (name + "-" + std::to_string(chunk_seconds));
  const auto outcome = nonsep::host::run_job(loaded, options);
  REQUIRE(outcome.steps_completed > 0);
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(options.output_directory)) {
    const std::string file = entry.path().filename().string();
    if (file == "summary.json") {
      json summary = read_json(entry.path());
      summary.erase("wall_seconds");
      summary["output"].erase("directory");
      files[file] = summary.dump();
    } else if (file != "results.h5") {  // HDF5 holds the same numbers as the CSV files (test_host_hdf5.cpp)
      files[file] = read_text(entry.path());
    }
  }
  return files;
}

}  // namespace

TEST_CASE("no output depends on where chunks end: one step each, sized by the clock, or grown eight times a chunk") {
  // The driver sizes chunks from the clock (run/chunk_sizer.hpp), so their ends differ from run to run: every path
  // that steps a chunk in one go must give what one step at a time gives, on the baseline kernel and on the one this
  // processor runs by default (whose multiply-adds round differently from the evaluation path's). paper2d (its orbits
  // diverge from step 14 on with dt = 0.01: blocks redo chunks step by step) through the state kernel (basic,
  // triplet, mpe), the tangent kernels with all four indicators, the comparators and mpe with tangent vectors
  // through the evaluation path, a Poincare section, a frequency map; blowup with states that diverge mid-run (with
  // and without a frequency map) and a plugin that fails mid-run.
  TemporaryFolder folder;
  use_test_plugins();
  const std::string paper2d = std::string(NONSEP_SHIPPED_PLUGIN_DIR) + "/paper2d.so";
  json orbits = json::array();
  for (int i = 0; i < 40; ++i) orbits.push_back({{"q", {0.5 - 0.0125 * i, 0.0}}, {"p", {0.0, 2.5 - 0.0125 * i}}});
  const json indicators = {{"lyapunov", {{"vectors", 4}, {"renormalize_every", 10}, {"every", 50}}},
                           {"megno", true},
                           {"sali", true},
                           {"gali", 4}};
  const auto on_paper2d = [&](json integrator, json analysis) {
    json job = {{"model", {{"plugin", paper2d}, {"parameters", {{"coupling", 0.2}}}}},
                {"integrator", std::move(integrator)},
                {"initial", orbits},
                {"time", {{"dt", 0.01}, {"steps", 300}}},
                {"output", {{"every", 0}}}};
    if (!analysis.is_null()) job["analysis"] = std::move(analysis);
    return job;
  };
  json diverging = json::array();
  for (int i = 0; i < 30; ++i) diverging.push_back(state(0.8 + 0.01 * i, 0.5));
  json diverging_job = blowup_job(diverging);
  diverging_job["time"] = {{"dt", 0.001}, {"steps", 500}};
  diverging_job["output"] = {{"every", 0}};
  const auto frequencies_of = [](json job) {
    job["analysis"] = {{"frequencies", {{"every", 5}}}};
    return job;
  };
  json failing_job = diverging_job;
  failing_job["model"]["parameters"] = {{"fail_above", 2.0}};
  const json poincare = {{"poincare", {{"component", "q1"}, {"value", 0.0}, {"direction", "+"}}}};
  const std::vector<std::pair<std::string, json>> jobs = {
      {"basic", on_paper2d({{"scheme", "basic"}}, nullptr)},
      {"triplet", on_paper2d({{"scheme", "triplet"}, {"order", "4/3"}}, nullptr)},
      {"mpe", on_paper2d({{"scheme", "mpe"}, {"order", 4}}, nullptr)},
      {"basic_tangents", on_paper2d({{"scheme", "basic"}}, indicators)},
      {"triplet_tangents", on_paper2d({{"scheme", "triplet"}, {"order", "4/3"}}, indicators)},
      {"mpe_tangents", on_paper2d({{"scheme", "mpe"}, {"order", 4}}, {{"lyapunov", {{"vectors", 2}}}})},
      {"gauss_tangents", on_paper2d({{"scheme", "gauss"}, {"stages", 2}}, indicators)},
      {"tao_tangents", on_paper2d({{"scheme", "tao"}, {"order", 4}}, {{"lyapunov", {{"vectors", 1}}}})},
      {"poincare", on_paper2d({{"scheme", "basic"}}, poincare)},
      {"frequencies", on_paper2d({{"scheme", "basic"}}, {{"frequencies", {{"every", 1}, {"spectra", 2}}}})},
      {"diverging", diverging_job},
      {"diverging_frequencies", frequencies_of(diverging_job)},
      {"failing", failing_job}};
  for (const std::string set : {"baseline", "default"}) {
    CAPTURE(set);
    if (set == "baseline")
      ::setenv("NONSEP_INSTRUCTION_SET", "baseline", 1);
    else
      ::unsetenv("NONSEP_INSTRUCTION_SET");  // the processor's own choice
    for (const auto& entry : jobs) {
      const std::string& name = entry.first;
      const json& job = entry.second;
      CAPTURE(name);
      const std::string run = name + "-" + set;
      const auto stepwise = run_in_chunks(folder, run, job, 0.0);
      REQUIRE(stepwise.count("trajectories.csv") == 1);
      if (name.starts_with("basic")) CHECK(stepwise.at("trajectories.csv").find(",diverged,") != std::string::npos);
      CHECK(run_in_chunks(folder, run, job, nonsep::host::run_chunk_seconds) == stepwise);
      CHECK(run_in_chunks(folder, run, job, 1e6) == stepwise);
    }
  }
  ::setenv("NONSEP_INSTRUCTION_SET", "baseline", 1);  // the tests' pin (test_main.cpp)
}

TEST_CASE("a plugin that declares \"thread_safe\": false runs on one thread with a note, as with --threads 1") {
  // global_state keeps its coupling in a global that every create() overwrites: a second instance for a second
  // thread would change every number. The host must keep to the one instance it checked the job with.
  TemporaryFolder folder;
  json states = json::array();
  for (int i = 0; i < 600; ++i) states.push_back(state(0.5 + 0.001 * i, 0.25));
  const auto file =
      write_job(folder / "job.json",
                blowup_job(states, json::object(), std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/global_state.so"));
  std::vector<std::string> tables;
  for (const char* threads : {"1", "2"}) {
    const auto out = folder / (std::string("out-") + threads);
    const auto result =
        run_nonsep({"run", "--quiet", "--threads", threads, "--output", out.string(), file.string()}, folder.path());
    CHECK(result.status == 0);
    CHECK((result.err.find("ran on one thread: the plugin 'global_state' declares \"thread_safe\": false") !=
           std::string::npos) == (std::string(threads) == "2"));
    tables.push_back(read_text(out / "trajectories.csv"));
  }
  CHECK(tables[0] == tables[1]);
}

TEST_CASE("--threads must be a whole number from 1 to 4096") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", quickstart_job());
  const auto zero = run_nonsep({"run", "--threads", "0", file.string()}, folder.path());
  CHECK(zero.status == 2);
  CHECK(zero.err.find("--threads: Value 0 not in range 1 to 4096") != std::string::npos);
  CHECK(run_nonsep({"run", "--threads", "two", file.string()}, folder.path()).status == 2);
}

TEST_CASE(
    "closest_return is the same whether the run steps in chunks (every = 0) or sample by sample, and on a replay") {
  TemporaryFolder folder;
  use_test_plugins();
  // Blowup with a diverging middle state: the block replays its first chunk step by step.
  json job = blowup_job(json::array({state(1.0, 0.5), state(1e103, 1.0), state(-0.5, 0.25)}));
  job["analysis"] = {{"closest_return_after", 0.01}};
  job["time"] = {{"dt", 0.001}, {"steps", 400}};
  job["output"] = {{"every", 1}};
  const json sampled = run_job(folder, "sampled", job, 1);
  job["output"] = {{"every", 0}};
  const json chunked = run_job(folder, "chunked", job, 1);
  for (std::size_t i : {0u, 2u}) {
    CAPTURE(i);
    REQUIRE(sampled["trajectories"][i]["closest_return"].is_object());
    CHECK(chunked["trajectories"][i]["closest_return"] == sampled["trajectories"][i]["closest_return"]);
    CHECK(chunked["trajectories"][i]["final"] == sampled["trajectories"][i]["final"]);
  }
  CHECK(chunked["trajectories"][1]["closest_return"] == sampled["trajectories"][1]["closest_return"]);
}

namespace {

// Counts the blocks a driver steps (ChunkObserver::prepare_blocks) and the trajectories it retires.
struct BlockCounter : nonsep::host::Observer, nonsep::host::ChunkObserver {
  std::size_t blocks = 0, retired = 0;
  void prepare_blocks(std::size_t count) override { blocks = count; }
  void on_retire(std::size_t, const nonsep::host::TrajectoryRecord&) override { ++retired; }
};

}  // namespace

TEST_CASE("blocks are sized from the ensemble, so that 71 trajectories are blocks that two threads share out") {
  using nonsep::host::run_block_size_for;
  CHECK(run_block_size_for(71) == 8);  // 9 blocks
  CHECK(run_block_size_for(600) == 64);
  CHECK(run_block_size_for(2048) == 256);
  CHECK(run_block_size_for(100000) == 256);
  CHECK(run_block_size_for(3) == 2);
  CHECK(run_block_size_for(1) == 2);
  const auto plugin = nonsep::host::load_plugin(std::string(NONSEP_SHIPPED_PLUGIN_DIR) + "/paper1d.so", "");
  const auto model = plugin.create(json::object());
  std::vector<double> q(71), p(71, 0.25);
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = 0.5 + 0.01 * static_cast<double>(i);
  for (const unsigned threads : {1u, 2u}) {
    CAPTURE(threads);
    nonsep::host::EnsembleSetup setup;
    setup.integrator = triplet_43();
    setup.time = nonsep::host::TimeGrid::of_steps(4, 0.01);
    setup.dimension = 1;
    setup.q = q;
    setup.p = p;
    setup.threads = threads;
    nonsep::host::EnsembleDriver driver(plugin, model, setup);
    BlockCounter counter;
    driver.add_observer(counter);
    CHECK(driver.run() == nonsep::host::DriverEnd::completed);
    CHECK(counter.blocks == 9);
    CHECK(counter.retired == 71);
  }
}

}  // namespace test_host_threads
