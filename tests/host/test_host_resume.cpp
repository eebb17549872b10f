// A resume is the run it continues, bit for bit, on the stepping the run uses: for every scheme, a run killed with
// SIGKILL or stopped with SIGINT after a checkpoint and resumed with --resume writes trajectory.csv and
// trajectories.csv (results.h5's /samples with output.format "hdf5") and the summary's numbers as the uninterrupted
// run does, with one and with two threads, on the widest instruction set this processor runs the plugin's kernel
// for (what a run uses unless NONSEP_INSTRUCTION_SET pins one) and on the baseline the other tests pin. Each case
// says which instruction set it ran. A resume that would step another way than its checkpoint was written with is
// refused with exit status 2, naming both and the variable that chooses the stepping.
#include <doctest/doctest.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#ifdef NONSEP_HAVE_HDF5
#include <bit>

#include "nonsep/host/output/hdf5_file.hpp"
#endif

namespace test_host_resume {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

// Sets NONSEP_INSTRUCTION_SET for the runs started in its lifetime ("" for the default: the widest set this
// processor runs), then puts the tests' pin back.
struct InstructionSet {
  explicit InstructionSet(const char* name) { ::setenv("NONSEP_INSTRUCTION_SET", name, 1); }
  ~InstructionSet() { ::setenv("NONSEP_INSTRUCTION_SET", "baseline", 1); }
  InstructionSet(const InstructionSet&) = delete;
  InstructionSet& operator=(const InstructionSet&) = delete;
};

// paper2d on a grid of side x side states (the grid at side 32), checkpointed every `every` steps.
json grid_job(json integrator, std::size_t side, std::uint64_t steps, std::uint64_t every, bool hdf5) {
  json job = {{"model", {{"plugin", "paper2d"}}},
              {"integrator", std::move(integrator)},
              {"initial",
               {{"grid",
                 {{"q", {{{"from", -0.5}, {"to", 0.5}, {"count", side}}, 0.1}},
                  {"p", {{{"from", -0.3}, {"to", 0.3}, {"count", side}}, 0.2}}}}}},
              {"time", {{"dt", 0.002}, {"steps", steps}}},
              {"output", {{"every", every / 2}}},
              {"checkpoint", {{"every_steps", every}, {"every_seconds", 0}}}};
  if (hdf5) job["output"]["format"] = "hdf5";
  return job;
}

// Everything of summary.json that must not depend on an interruption: states, energies, statuses, counts.
json numbers_of(const json& summary) {
  return json::array({summary["trajectories"], summary["counts"], summary["status"], summary["time"]["steps_completed"],
                      summary["energy"]});
}

#ifdef NONSEP_HAVE_HDF5
// The bits of every number of results.h5's /samples (q, p, t, step), dataset after dataset.
std::vector<std::uint64_t> sample_bits(const std::filesystem::path& path) {
  using namespace nonsep::host;
  const Hdf5File file = Hdf5File::open(path);
  std::vector<std::uint64_t> bits;
  for (const char* name : {"/samples/q", "/samples/p", "/samples/t", "/samples/step"}) {
    const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), name, H5P_DEFAULT), H5Dclose, name);
    const Hdf5Handle space = file.own(H5Dget_space(dataset.get()), H5Sclose, name);
    std::vector<double> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
    const bool steps = std::string(name) == "/samples/step";
    std::vector<std::uint64_t> integers(steps ? values.size() : 0);
    file.check(H5Dread(dataset.get(), steps ? H5T_NATIVE_UINT64 : H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                       steps ? static_cast<void*>(integers.data()) : static_cast<void*>(values.data())),
               name);
    bits.push_back(values.size());
    for (double x : values) bits.push_back(std::bit_cast<std::uint64_t>(x));
    bits.insert(bits.end(), integers.begin(), integers.end());
  }
  return bits;
}
#endif

// What a run left that a resume must reproduce.
struct Outputs {
  std::string samples, table;
  std::vector<std::uint64_t> h5_samples;
  json summary;
};

Outputs outputs_of(const std::filesystem::path& folder) {
  Outputs outputs;
  outputs.summary = read_run(folder);
  outputs.table = read_text(folder / "trajectories.csv");
  if (std::filesystem::exists(folder / "trajectory.csv")) outputs.samples = read_text(folder / "trajectory.csv");
#ifdef NONSEP_HAVE_HDF5
  if (std::filesystem::exists(folder / "results.h5")) outputs.h5_samples = sample_bits(folder / "results.h5");
#endif
  return outputs;
}

// Starts `nonsep run` of `file` into `output` with `threads`, stops it with `signal` once its checkpoint is at step
// `at_least` or later, and returns the step of the checkpoint it left.
std::uint64_t stop_after_checkpoint(const std::filesystem::path& file, const std::filesystem::path& output,
                                    const std::string& threads, int signal, std::uint64_t at_least,
                                    const std::filesystem::path& folder) {
  const auto process =
      start_nonsep({"run", "--quiet", "--threads", threads, "--output", output.string(), file.string()}, folder);
  const auto checkpoint_step = [&] { return read_json(output / "checkpoint.json")["step"].get<std::uint64_t>(); };
  const bool reached = wait_until([&] {
    try {
      return checkpoint_step() >= at_least;
    } catch (const std::exception&) {
      return false;
    }
  });
  ::kill(process.pid, signal);
  const auto stopped = finish(process, std::chrono::seconds(60));
  REQUIRE(reached);
  CHECK(stopped.status == 128 + signal);  // SIGINT: nonsep's own exit status 130
  return checkpoint_step();
}

// The job `job` run uninterrupted, then stopped by each signal (SIGKILL with `kill_threads`, SIGINT with the other
// count) and resumed: every output as the uninterrupted run's. Returns the instruction set the runs used.
std::string check_resumes(const json& job, const std::string& name, const std::string& kill_threads,
                          std::uint64_t checkpoint) {
  TemporaryFolder folder;
  const auto file = write_job(folder / (name + ".json"), job);
  const auto reference_run = run_nonsep(
      {"run", "--quiet", "--threads", "1", "--output", (folder / "reference").string(), file.string()}, folder.path());
  INFO("stderr: " << reference_run.err);
  REQUIRE(reference_run.status == 0);
  const Outputs reference = outputs_of(folder / "reference");
  for (const int signal : {SIGKILL, SIGINT}) {
    CAPTURE(signal);
    const std::string threads = signal == SIGKILL ? kill_threads : (kill_threads == "1" ? "2" : "1");
    CAPTURE(threads);
    const auto out = folder / ("stopped_" + std::to_string(signal));
    const auto step = stop_after_checkpoint(file, out, threads, signal, checkpoint, folder.path());
    INFO("stopped at step " << step);
    const auto resumed = run_nonsep(
        {"run", "--quiet", "--resume", "--threads", threads, "--output", out.string(), file.string()}, folder.path());
    INFO("resumed: " << resumed.err);
    REQUIRE(resumed.status == 0);
    const Outputs outputs = outputs_of(out);
    CHECK(outputs.samples == reference.samples);
    CHECK(outputs.h5_samples == reference.h5_samples);
    CHECK(outputs.table == reference.table);
    CHECK(numbers_of(outputs.summary) == numbers_of(reference.summary));
    CHECK(outputs.summary["stepping"]["instruction_set"] == reference.summary["stepping"]["instruction_set"]);
  }
  const json& set = reference.summary["stepping"]["instruction_set"];
  return set.is_string() ? set.get<std::string>() : "none (the evaluation path)";
}

// The schemes of the catalogue on `instruction_set` ("" for the default), CSV and HDF5 in turn, SIGKILL with one or
// two threads in turn and SIGINT with the other: Chin's schemes on a 32 x 32 grid, and with `comparators` the
// comparators (which step through the evaluation path whatever the set, and are slower) on a smaller one.
void check_schemes(const char* instruction_set, bool comparators) {
  InstructionSet pin(instruction_set);
  std::vector<std::pair<json, std::size_t>> schemes = {{{{"scheme", "basic"}, {"t2", -3.0}}, 32},
                                                       {{{"scheme", "triplet"}, {"order", "4/3"}}, 32},
                                                       {{{"scheme", "mpe"}, {"order", "4/3"}}, 32}};
  if (comparators)
    schemes.insert(schemes.end(),
                   {{{{"scheme", "tao"}}, 6}, {{{"scheme", "implicit_midpoint"}}, 4}, {{{"scheme", "gauss"}}, 4}});
  bool hdf5 = false;
  std::string kill_threads = "2";
  for (const auto& [integrator, side] : schemes) {
    const std::string scheme = integrator["scheme"];
    CAPTURE(scheme);
#ifdef NONSEP_HAVE_HDF5
    hdf5 = !hdf5;
#endif
    CAPTURE(hdf5);
    const json job = grid_job(integrator, side, 6000, 1000, hdf5);
    const std::string used = check_resumes(job, scheme, kill_threads, 1000);
    const std::string pinned = *instruction_set ? instruction_set : "unset";
    const std::string text = "resumed " + scheme + (hdf5 ? " (hdf5)" : " (csv)") + " on instruction set " + used +
                             " (NONSEP_INSTRUCTION_SET " + pinned + ")";
    MESSAGE(text);
    kill_threads = kill_threads == "1" ? "2" : "1";
  }
}

}  // namespace

TEST_CASE("resume on the default kernel (the widest set this processor runs): every scheme bit for bit") {
  check_schemes("", true);
}

TEST_CASE("resume on the baseline kernel: Chin's schemes bit for bit") { check_schemes("baseline", false); }

TEST_CASE("resume under another instruction set or path than its checkpoint's: exit 2 naming both, nothing changed") {
  TemporaryFolder folder;
  const auto file =
      write_job(folder / "job.json", grid_job({{"scheme", "triplet"}, {"order", "4/3"}}, 8, 6000, 1000, false));
  std::string widest;
  {
    InstructionSet pin("");
    const auto probe =
        run_nonsep({"run", "--quiet", "--output", (folder / "probe").string(), file.string()}, folder.path());
    REQUIRE(probe.status == 0);
    widest = read_run(folder / "probe")["stepping"]["instruction_set"].get<std::string>();
  }
  // From the baseline kernel to the evaluation path, and to the widest set when this processor runs a wider one.
  std::vector<std::pair<std::string, std::string>> changes = {{"baseline", "evaluation"}};
  if (widest != "x86-64") changes.push_back({"baseline", ""});
  for (const auto& change : changes) {
    const std::string& written = change.first;  // not a structured binding: CAPTURE's lambda takes it
    const std::string& resumed = change.second;
    CAPTURE(written);
    CAPTURE(resumed);
    const auto out = folder / ("out_" + written + "_" + resumed);
    {
      InstructionSet pin(written.c_str());
      stop_after_checkpoint(file, out, "1", SIGKILL, 1000, folder.path());
    }
    const std::string checkpoint = read_text(out / "checkpoint.json");
    const std::string samples = read_text(out / "trajectory.csv");
    InstructionSet pin(resumed.c_str());
    const auto refused =
        run_nonsep({"run", "--quiet", "--resume", "--output", out.string(), file.string()}, folder.path());
    CHECK(refused.status == 2);
    INFO("stderr: " << refused.err);
    CHECK(refused.err.find("cannot resume") != std::string::npos);
    CHECK(refused.err.find("the plugin's x86-64 kernel") != std::string::npos);
    CHECK(refused.err.find(resumed == "evaluation" ? "the evaluation path" : "the plugin's " + widest + " kernel") !=
          std::string::npos);
    CHECK(refused.err.find("NONSEP_INSTRUCTION_SET=x86-64") != std::string::npos);
    CHECK(read_text(out / "checkpoint.json") == checkpoint);
    CHECK(read_text(out / "trajectory.csv") == samples);
    InstructionSet as_advised(written.c_str());
    CHECK(run_nonsep({"run", "--quiet", "--resume", "--output", out.string(), file.string()}, folder.path()).status ==
          0);
  }
}

TEST_CASE("a resume with analysis.error_estimate added belongs to a different job: exit 2 naming analysis") {
  TemporaryFolder folder;
  json job = grid_job({{"scheme", "triplet"}, {"order", "4/3"}}, 32, 6000, 1000, false);
  const auto file = write_job(folder / "job.json", job);
  const auto out = folder / "out";
  kill_after_checkpoint(file, out, 1000, folder.path());
  job["analysis"] = {{"error_estimate", true}};
  const auto added = write_job(folder / "added.json", job);
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", out.string(), added.string()}, folder.path());
  INFO(resumed.err);
  CHECK(resumed.status == 2);
  CHECK(resumed.err.find("belongs to a different job: its analysis differs") != std::string::npos);
  CHECK(resumed.err.find("damaged") == std::string::npos);
}

TEST_CASE("scheme auto: an interrupted run resumes with the choice its checkpoint recorded, as the run it chose") {
  TemporaryFolder folder;
  // dt 0.05 is the output grid: the step chosen for 1e-9 is a fraction of it (output.every and the checkpoint's
  // every_steps count the grid's steps).
  json job = grid_job({{"scheme", "auto"}, {"tolerance", 1e-9}}, 16, 200, 20, false);
  job["time"]["dt"] = 0.05;
  const auto file = write_job(folder / "auto.json", job);
  const auto out = folder / "out";
  const auto process = start_nonsep({"run", "--output", out.string(), file.string()}, folder.path());
  const bool saved = wait_until([&] { return std::filesystem::exists(out / "checkpoint.json"); });
  ::kill(process.pid, SIGINT);
  const auto stopped = finish(process, std::chrono::seconds(120));
  REQUIRE(saved);
  INFO("stopped: " << stopped.err);
  REQUIRE(stopped.status == 130);
  CHECK(stopped.err.find("--resume` continues from there") != std::string::npos);
  const json recorded = json::parse(read_json(out / "checkpoint.json")["scheme_choice"].get<std::string>());
  const auto resumed = run_nonsep({"run", "--resume", "--output", out.string(), file.string()}, folder.path());
  INFO("resumed: " << resumed.err);
  REQUIRE(resumed.status == 0);
  CHECK(resumed.out.find("as the interrupted run chose") != std::string::npos);
  const json summary = read_json(out / "summary.json");
  // No pilots again: the choice (its pilots' wall time included) is the recorded one.
  CHECK(summary["scheme_choice"]["pilot_cost"] == recorded["pilot_cost"]);
  CHECK(summary["scheme_choice"]["chosen"] == recorded["chosen"]);
  const std::uint64_t m = recorded["subdivision"].get<std::uint64_t>();
  // The run it chose, written out as a job: the same files, bit for bit.
  const std::string chosen = recorded["chosen"].get<std::string>();  // "gauss 6", "triplet 8/3": scheme and order
  const std::string scheme = chosen.substr(0, chosen.find(' ')), order = chosen.substr(chosen.find(' ') + 1);
  json fixed = job;
  fixed["integrator"] = {{"scheme", scheme}};
  if (scheme == "gauss")
    fixed["integrator"]["stages"] = std::stoi(order) / 2;
  else
    fixed["integrator"]["order"] = order;
  fixed["time"] = {{"dt", 0.05 / static_cast<double>(m)}, {"steps", 200 * m}};
  fixed["output"]["every"] = 10 * m;
  const auto fixed_file = write_job(folder / "fixed.json", fixed);
  const auto reference =
      run_nonsep({"run", "--quiet", "--output", (folder / "fixed").string(), fixed_file.string()}, folder.path());
  INFO("fixed: " << reference.err);
  REQUIRE(reference.status == 0);
  CHECK(read_text(out / "trajectories.csv") == read_text(folder / "fixed" / "trajectories.csv"));
  CHECK(read_text(out / "trajectory.csv") == read_text(folder / "fixed" / "trajectory.csv"));
}

TEST_CASE("scheme auto: a folder the run may not use is refused before the pilots run") {
  TemporaryFolder folder;
  const auto file =
      write_job(folder / "auto.json", grid_job({{"scheme", "auto"}, {"tolerance", 1e-8}}, 2, 100, 10, false));
  std::filesystem::create_directories(folder / "out");
  write_text(folder / "out" / "checkpoint.json", "{}");
  const auto refused = run_nonsep({"run", "--output", (folder / "out").string(), file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(refused.err.find("holds the checkpoint of an interrupted run") != std::string::npos);
  CHECK(refused.out.find("auto: ") == std::string::npos);  // nothing chosen: no pilot ran
}

TEST_CASE(
    "scheme auto: SIGINT during the pilots stops them with exit status 130 and a message, leaving no checkpoint") {
  TemporaryFolder folder;
  // One state of a chain of 2^16 sites: pilots of seconds, stopped within a chunk.
  const std::size_t sites = std::size_t{1} << 16;
  std::vector<double> q(sites), p(sites, 0.0);
  for (std::size_t i = 0; i < sites; ++i) q[i] = 0.1 * std::sin(0.01 * static_cast<double>(i));
  const json job = {{"model", {{"plugin", "lattice_chain"}, {"parameters", {{"sites", sites}}}}},
                    {"integrator", {{"scheme", "auto"}, {"tolerance", 1e-12}}},
                    {"initial", {{"q", q}, {"p", p}}},
                    {"time", {{"dt", 0.5}, {"t_end", 1000.0}}},
                    {"output", {{"every", 0}}}};
  const auto file = write_job(folder / "chain.json", job);
  const auto out = folder / "out";
  const auto process = start_nonsep({"run", "--output", out.string(), file.string()}, folder.path());
  // The folder is taken before the pilots start.
  const bool taken = wait_until([&] { return std::filesystem::exists(out / ".nonsep-run.json"); });
  ::kill(process.pid, SIGINT);
  const auto stopped = finish(process, std::chrono::seconds(120));
  REQUIRE(taken);
  INFO(stopped.err);
  CHECK(!stopped.killed);
  CHECK(stopped.status == 130);
  CHECK(stopped.err.find("stopped by SIGINT during the pilot runs of scheme auto") != std::string::npos);
  CHECK(!std::filesystem::exists(out / "checkpoint.json"));
  CHECK(!std::filesystem::exists(out / "summary.json"));
}

}  // namespace test_host_resume
