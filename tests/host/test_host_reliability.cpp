// Reliability of the `nonsep` executable, end to end: every kind of broken or misbehaving plugin gets its own exit
// status and message, and whatever a run wrote before it stopped is complete and parses; SIGINT and SIGTERM stop a
// run cleanly even inside a very slow plugin; an interrupted or killed run resumed with --resume ends with the same
// states and the same trajectory.csv, bit for bit, as an uninterrupted one.
#include <doctest/doctest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "address_sanitizer.hpp"
#include "host_test_support.hpp"
#include "nonsep/host/output/content_hash.hpp"

namespace test_host_reliability {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

json state(double q, double p) { return {{"q", {q}}, {"p", {p}}}; }

json job_with(std::string plugin, json initial, json parameters = json::object(),
              json time = {{"dt", 0.01}, {"steps", 200}}) {
  return {{"model", {{"plugin", std::move(plugin)}, {"parameters", std::move(parameters)}}},
          {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}, {"t2", -2.0}}},
          {"initial", std::move(initial)},
          {"time", std::move(time)},
          {"output", {{"directory", "out"}, {"every", 1}}}};
}

std::string broken_plugin(const std::string& name) {
  return std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/" + name + ".so";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Every row of trajectory.csv ends with a newline and has the header's columns; every cell but the energy ones is a
// number that parses completely; the energy cells are numbers or empty. Returns the rows after the header.
std::vector<std::vector<std::string>> check_complete_csv(const std::filesystem::path& path, std::size_t dimension) {
  const std::string text = read_text(path);
  REQUIRE(!text.empty());
  CHECK(text.back() == '\n');
  auto rows = read_csv(path);
  REQUIRE(!rows.empty());
  const std::size_t columns = 3 + 2 * dimension + 2;
  REQUIRE(rows[0].size() == columns);
  CHECK(rows[0][0] == "trajectory");
  rows.erase(rows.begin());
  for (const auto& row : rows) {
    REQUIRE(row.size() == columns);
    for (std::size_t c = 0; c < columns; ++c) {
      if (c >= columns - 2 && row[c].empty()) continue;
      double x = 0.0;
      const auto result = std::from_chars(row[c].data(), row[c].data() + row[c].size(), x);
      INFO("cell " << c << ": \"" << row[c] << "\"");
      CHECK((result.ec == std::errc() && result.ptr == row[c].data() + row[c].size()));
    }
  }
  return rows;
}

struct Ran {
  Result result;
  json summary;
};

// Runs `job` from folder/job.json; the summary must exist and parse.
Ran run(const TemporaryFolder& folder, const json& job, int expected_status, std::vector<std::string> extra = {}) {
  const auto file = write_job(folder / "job.json", job);
  std::vector<std::string> args{"run", "--quiet"};
  args.insert(args.end(), extra.begin(), extra.end());
  args.push_back(file.string());
  Ran ran{run_nonsep(args, folder.path()), {}};
  INFO("stderr: " << ran.result.err);
  CHECK(ran.result.status == expected_status);
  CHECK(!ran.result.killed);
  REQUIRE(std::filesystem::exists(folder / "out/summary.json"));
  ran.summary = read_run(folder / "out");
  return ran;
}

// Waits until `path` exists and has more than `bytes` bytes (at most 30 s).
void wait_for_file(const std::filesystem::path& path, std::size_t bytes = 0) {
  const bool appeared = wait_until([&] {
    std::error_code error;
    return std::filesystem::exists(path, error) && std::filesystem::file_size(path, error) > bytes && !error;
  });
  if (!appeared) FAIL("waited in vain for " << path.string());
}

}  // namespace

TEST_CASE(
    "a plugin that cannot be loaded: validate and run exit 2 naming /model/plugin and the defect, nothing is run") {
  const std::pair<const char*, const char*> cases[] = {
      {"missing_entry_symbol", "does not export the symbol 'nonsep_plugin'"},
      {"version_1_entry", "uses plugin ABI version 1 (it exports 'nonsep_plugin_entry')"},
      {"wrong_abi_version", "uses plugin ABI version 2 but this host uses version 6"},
      {"wrong_table_size", "has a function table of"},
      {"invalid_metadata_json", "is not valid JSON"},
      {"metadata_names_another", "declares the name 'someone_else'"},
      {"missing_grad_V", "lacks the required function grad_V"},
      {"capability_mismatch", "says capability \"hessian_T\" is true"},
      {"not_a_library", "as a shared library"},
  };
  for (const auto& [name, message] : cases) {
    const std::string case_name(name);  // clang 14 cannot capture a structured binding
    CAPTURE(case_name);
    TemporaryFolder folder;
    const auto file = write_job(folder / "job.json", job_with(broken_plugin(name), state(0.5, 0.0)));
    for (const char* command : {"validate", "run"}) {
      const auto result = run_nonsep({command, file.string()}, folder.path());
      INFO(command << " stderr: " << result.err);
      CHECK(result.status == 2);
      CHECK(!result.killed);
      CHECK(contains(result.err, "/model/plugin: found \"" + broken_plugin(name) + "\", which cannot be loaded"));
      CHECK(contains(result.err, message));
    }
    CHECK(!std::filesystem::exists(folder / "out"));
  }
}

TEST_CASE("create failing: exit 2 naming /model/parameters and the plugin's reason, nothing is run") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json",
                              job_with(broken_plugin("create_failing"), state(0.5, 0.0), {{"inner_radius", 3.0}}));
  for (const char* command : {"validate", "run"}) {
    const auto result = run_nonsep({command, file.string()}, folder.path());
    INFO(command << " stderr: " << result.err);
    CHECK(result.status == 2);
    CHECK(contains(result.err, "/model/parameters: found {\"inner_radius\":3.0}, refused by the plugin"));
    CHECK(contains(result.err, "parameter 'inner_radius' must be smaller than 'outer_radius'"));
  }
  CHECK(!std::filesystem::exists(folder / "out"));
}

TEST_CASE("an error status mid-run: the trajectory fails with the plugin's message, exit 1, outputs complete") {
  TemporaryFolder folder;
  // V = -log(1 - q^2): grad V refuses |q| >= 1. Under H = p^2 V''(q) the speed 2 sqrt(H V''(q)) grows without
  // bound as q approaches 1, which it reaches in finite time: from q = 0.5, p = 0.5 after about ten steps.
  const Ran ran = run(folder, job_with(broken_plugin("evaluation_fails"), state(0.5, 0.5)), 1);
  CHECK(contains(ran.result.err, "failed: 1 trajectory (0 completed, 1 failed)"));
  CHECK(contains(ran.result.err, "trajectory 0 failed: the model failed at step"));
  CHECK(contains(ran.result.err, "needs |q| < 1"));
  const json& trajectory = ran.summary["trajectories"][0];
  CHECK(ran.summary["status"] == "failed");
  CHECK(trajectory["status"] == "failed");
  const auto last_step = trajectory["final"]["step"].get<std::uint64_t>();
  CHECK(last_step > 1);
  const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
  REQUIRE(rows.size() == last_step + 1);
  CHECK(rows.back()[1] == std::to_string(last_step));
}

TEST_CASE("an exception inside the plugin: the trajectory fails with the exception's text, exit 1, outputs complete") {
  TemporaryFolder folder;
  const Ran ran = run(folder, job_with(broken_plugin("evaluation_throws"), state(0.5, 0.5)), 1);
  // grad T is first needed for the energy H0 = grad T . Hess V . grad T, before the first step.
  CHECK(contains(ran.result.err, "trajectory 0 failed: the energy could not be evaluated at step 0"));
  CHECK(contains(ran.result.err, "(internal error): exception in grad_T: deliberate bug"));
  CHECK(ran.summary["trajectories"][0]["status"] == "failed");
  const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
  REQUIRE(rows.size() == 1);
  CHECK(rows[0][1] == "0");
}

TEST_CASE("an exception inside the plugin partway: every row before it complete, the failure at the step after") {
  TemporaryFolder folder;
  // H_TTV = p^2 from (0.5, 0.5): q = 0.5 + t (to the method's error), past 1.1 at t = 0.6. grad V throws where
  // |q| > 1.1; the stages of a step reach well beyond its ends (the drifts of eq. expalg are of size
  // cbrt(dt) = 0.2 here, forwards and backwards), so the first throw comes at some step before t = 0.6.
  const Ran ran = run(folder,
                      job_with(broken_plugin("evaluation_throws"), state(0.5, 0.5),
                               {{"throw_above_p", 10.0}, {"throw_above_q", 1.1}}, {{"dt", 0.01}, {"steps", 200}}),
                      1);
  const json& trajectory = ran.summary["trajectories"][0];
  CHECK(trajectory["status"] == "failed");
  const auto last_step = trajectory["final"]["step"].get<std::uint64_t>();
  CHECK(last_step >= 10);
  CHECK(last_step < 60);
  CHECK(trajectory["final"]["q"][0].get<double>() == doctest::Approx(0.5 + 0.01 * last_step).epsilon(1e-3));
  const auto error = trajectory["message"].get<std::string>();
  CHECK(contains(error, "the model failed at step " + std::to_string(last_step + 1) + ": "));
  CHECK(contains(error, "exception in grad_V: deliberate bug: q beyond the table in grad_V"));
  // Every step before the failure is in trajectory.csv, complete.
  const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
  REQUIRE(rows.size() == last_step + 1);
  for (std::size_t k = 0; k < rows.size(); ++k) CHECK(rows[k][1] == std::to_string(k));
}

TEST_CASE("NaN or Inf from the plugin after N calls: the trajectory diverges where it happens, exit 1") {
  for (const char* parameter : {"nan_after", "inf_after"}) {
    CAPTURE(std::string(parameter));
    TemporaryFolder folder;
    const Ran ran = run(folder, job_with("blowup", state(0.5, 0.5), {{parameter, 30}}), 1);
    CHECK(contains(ran.result.err, "diverged: 1 trajectory (0 completed, 1 diverged)"));
    CHECK(contains(ran.result.err, "trajectory 0 diverged at step"));
    const json& trajectory = ran.summary["trajectories"][0];
    CHECK(ran.summary["status"] == "diverged");
    CHECK(trajectory["status"] == "diverged");
    CHECK(!trajectory.contains("error"));
    const auto step = trajectory["stop"]["step"].get<std::uint64_t>();
    CHECK(step > 1);
    CHECK(trajectory["stop"]["t"].get<double>() == doctest::Approx(0.01 * static_cast<double>(step)));
    // The kick with the NaN (or inf) grad V spoils p, the next drift q; both are non-finite after the step, and q
    // is reported first.
    CHECK(trajectory["stop"]["variable"] == "q[0]");
    CHECK(trajectory["final"]["step"] == step - 1);
    const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
    REQUIRE(rows.size() == step);
    for (const auto& row : rows)
      for (std::size_t c = 2; c < 5; ++c) CHECK(std::isfinite(std::stod(row[c])));
  }
}

TEST_CASE("a shipped model whose gradient overflows: diverged, not failed (the SDK passes non-finite numbers on)") {
  TemporaryFolder folder;
  // paper1d: grad V = q + q^3 / 3 overflows at q = 1e103; the other state completes.
  const Ran ran = run(folder, job_with("paper1d", json::array({state(1e103, 0.0), state(1.0, 0.0)})), 1);
  CHECK(ran.summary["status"] == "diverged");
  const json& diverged = ran.summary["trajectories"][0];
  CHECK(diverged["status"] == "diverged");
  CHECK(diverged["stop"]["step"] == 1);
  CHECK(diverged["stop"]["variable"] == "q[0]");
  CHECK(ran.summary["trajectories"][1]["status"] == "completed");
  CHECK(ran.summary["counts"]["diverged"] == 1);
  CHECK(ran.summary["counts"]["failed"] == 0);
  CHECK(contains(ran.result.err, "trajectory 0 diverged at step 1, t = 0.01 (q[0] is not finite)"));
  check_complete_csv(folder / "out/trajectory.csv", 1);
}

TEST_CASE("a very slow plugin: SIGINT or SIGTERM ends the run after the current step, outputs complete, 130 or 143") {
  for (const int signal : {SIGINT, SIGTERM}) {
    CAPTURE(signal);
    TemporaryFolder folder;
    // 40 ms per grad V call: a step of triplet 4/3 takes several tenths of a second.
    const auto file = write_job(folder / "job.json", job_with("blowup", state(0.5, 0.5), {{"sleep_ms", 40}},
                                                              {{"dt", 0.001}, {"steps", 100000}}));
    const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
    wait_for_file(folder / "out/trajectory.csv", 60);  // the header and at least a row: flushed after ~1 s
    REQUIRE(::kill(process.pid, signal) == 0);
    const auto result = finish(process, std::chrono::seconds(30));  // fails the test if the run does not stop
    INFO("stderr: " << result.err);
    CHECK(!result.killed);
    CHECK(result.status == (signal == SIGINT ? 130 : 143));
    CHECK(contains(result.err, signal == SIGINT ? "stopped by SIGINT" : "stopped by SIGTERM"));
    CHECK(contains(result.err, "--resume` continues from there"));
    const json summary = read_run(folder / "out");
    CHECK(summary["status"] == "interrupted");
    const auto completed = summary["time"]["steps_completed"].get<std::uint64_t>();
    CHECK(completed > 0);
    const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
    CHECK(rows.back()[1] == std::to_string(completed));
    CHECK(std::filesystem::exists(folder / "out/checkpoint.json"));
  }
}

TEST_CASE("a signal delivered twice at once (timeout signals the process and its group) stops the run once") {
  TemporaryFolder folder;
  const auto file = write_job(
      folder / "job.json", job_with("blowup", state(0.5, 0.5), {{"sleep_ms", 40}}, {{"dt", 0.001}, {"steps", 100000}}));
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_for_file(folder / "out/trajectory.csv", 60);
  // Pending signals are delivered lowest number first: SIGUSR1 stops the run, the two SIGTERMs are repeats.
  for (const int signal : {SIGTERM, SIGTERM, SIGUSR1}) REQUIRE(::kill(process.pid, signal) == 0);
  const auto result = finish(process, std::chrono::seconds(30));
  INFO("stderr: " << result.err);
  CHECK(!result.killed);
  CHECK(result.status == 143);
  CHECK(contains(result.err, "stopped by SIG"));
  CHECK(read_run(folder / "out")["status"] == "interrupted");
  CHECK(std::filesystem::exists(folder / "out/checkpoint.json"));
}

TEST_CASE("a second signal well after the first is the user insisting: the process ends at once, killed by it") {
  TemporaryFolder folder;
  // 1.5 s per grad V call: the step the first signal lets finish outlasts the window of repeated deliveries.
  const auto file = write_job(folder / "job.json", job_with("blowup", state(0.5, 0.5), {{"sleep_ms", 1500}},
                                                            {{"dt", 0.001}, {"steps", 100000}}));
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_for_file(folder / "out/trajectory.csv", 60);
  REQUIRE(::kill(process.pid, SIGINT) == 0);
  // The window is the quantity under test: a repeat within 1 s is ignored, one after it is not.
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  REQUIRE(::kill(process.pid, SIGINT) == 0);
  const auto result = finish(process, std::chrono::seconds(30));
  CHECK(result.killed);
  CHECK(result.status == 128 + SIGINT);
}

namespace {

// An ensemble whose middle state diverges at once (retired before any checkpoint) and whose others run ~1 s in a
// release build (long enough to be killed between checkpoints, which come every few milliseconds).
json resumable_job() {
  json job = job_with("paper1d", json::array({state(2.0, 0.0), state(1e103, 0.0), state(1.0, 0.5)}), json::object(),
                      {{"dt", 1e-6}, {"steps", 1500000}});
  job["output"]["every"] = 997;  // checkpoints fall between samples, so cutting the file back matters
  job["checkpoint"] = {{"every_steps", 20000}, {"every_seconds", 0}};
  return job;
}

// Everything that must not depend on an interruption: states, energies, statuses, divergence, counts.
json numbers_of(const json& summary) {
  json numbers = summary["trajectories"];
  numbers.push_back(summary["counts"]);
  numbers.push_back(summary["status"]);
  numbers.push_back(summary["time"]["steps_completed"]);
  return numbers;
}

}  // namespace

TEST_CASE("resume after SIGKILL and after SIGINT: the same final states and trajectory.csv, bit for bit") {
  TemporaryFolder reference;
  const Ran uninterrupted = run(reference, resumable_job(), 1);
  CHECK(!std::filesystem::exists(reference / "out/checkpoint.json"));  // a run that ended removes it
  const std::string reference_csv = read_text(reference / "out/trajectory.csv");

  for (const int signal : {SIGKILL, SIGINT}) {
    CAPTURE(signal);
    TemporaryFolder folder;
    const auto file = write_job(folder / "job.json", resumable_job());
    const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
    // Killed once a checkpoint past the first exists, so the run is stopped between two later checkpoints.
    REQUIRE(wait_until([&] {
      try {
        return read_json(folder / "out/checkpoint.json")["step"].get<std::uint64_t>() >= 40000;
      } catch (const std::exception&) {
        return false;  // not written yet
      }
    }));
    REQUIRE(::kill(process.pid, signal) == 0);
    const auto stopped = finish(process, std::chrono::seconds(30));
    CHECK(stopped.status == (signal == SIGKILL ? 128 + SIGKILL : 130));
    const json checkpoint = read_json(folder / "out/checkpoint.json");
    const auto checkpoint_step = checkpoint["step"].get<std::uint64_t>();
    INFO("stopped at step " << checkpoint_step);
    CHECK(checkpoint_step > 0);
    CHECK(checkpoint_step < 1500000);
    if (signal == SIGKILL) CHECK(checkpoint_step % 20000 == 0);

    const auto resumed = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
    INFO("stderr: " << resumed.err);
    CHECK(resumed.status == 1);  // the diverged state, as in the uninterrupted run
    const json summary = read_run(folder / "out");
    CHECK(numbers_of(summary) == numbers_of(uninterrupted.summary));
    CHECK(summary["trajectories"][1]["status"] == "diverged");
    CHECK(read_text(folder / "out/trajectory.csv") == reference_csv);
    // The resumed run evaluates once more the gradient its first basic step would have reused: one grad V (TTV)
    // per state active at the checkpoint (counts are per state).
    const auto& counts = summary["evaluations"];
    const auto& reference_counts = uninterrupted.summary["evaluations"];
    CHECK(counts["grad_T"] == reference_counts["grad_T"]);
    CHECK(counts["grad_V"].get<std::uint64_t>() - reference_counts["grad_V"].get<std::uint64_t>() ==
          checkpoint["active"]["trajectories"].size());
    CHECK(!std::filesystem::exists(folder / "out/checkpoint.json"));
  }
}

TEST_CASE("resume refuses a missing checkpoint and another job's, with exit 2 and what to do") {
  TemporaryFolder folder;
  json job = resumable_job();
  job["time"]["steps"] = 10;
  const auto file = write_job(folder / "job.json", job);
  const auto missing = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
  CHECK(missing.status == 2);
  CHECK(contains(missing.err, "nonsep: cannot resume: nothing to resume: there is no"));
  CHECK(contains(missing.err, "checkpoint.json"));

  // A checkpoint of this job, left by SIGTERM, then the same job with another dt.
  job["initial"] = state(1.0, 0.0);
  job["time"]["steps"] = 100000000;
  job["checkpoint"] = {{"every_steps", 1000}, {"every_seconds", 0}};
  write_job(file, job);
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_for_file(folder / "out/checkpoint.json");
  REQUIRE(::kill(process.pid, SIGTERM) == 0);
  CHECK(finish(process).status == 143);
  job["time"]["dt"] = 2e-6;
  write_job(file, job);
  const auto other = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
  CHECK(other.status == 2);
  CHECK(contains(other.err, "belongs to a different job: its time differs"));
  CHECK(contains(other.err, "run with --force to start over"));

  // A damaged checkpoint is refused, not trusted.
  job["time"]["dt"] = 1e-6;
  write_job(file, job);
  write_text(folder / "out/checkpoint.json", "{\"format\": \"nonsep checkpoint 1\", \"job_fingerprint\": 7");
  const auto damaged = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
  CHECK(damaged.status == 2);
  CHECK(contains(damaged.err, "is damaged (not JSON"));
}

TEST_CASE("resume checks content: an edited checkpoint or trajectory.csv is refused with exit 2, nothing changed") {
  TemporaryFolder folder;
  json job = resumable_job();
  job["initial"] = state(1.0, 0.0);
  job["time"]["steps"] = 100000000;
  job["checkpoint"] = {{"every_steps", 1000}, {"every_seconds", 0}};
  const auto file = write_job(folder / "job.json", job);
  const auto process = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_for_file(folder / "out/checkpoint.json");
  REQUIRE(::kill(process.pid, SIGTERM) == 0);
  CHECK(finish(process).status == 143);
  const auto checkpoint_path = folder / "out/checkpoint.json";
  const std::string original = read_text(checkpoint_path);
  const json checkpoint = read_json(checkpoint_path);
  REQUIRE(checkpoint["active"]["trajectories"].size() == 1);
  const auto resume = [&](const std::string& expected) {
    const std::string csv_before = read_text(folder / "out/trajectory.csv");
    const auto resumed = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
    INFO("stderr: " << resumed.err);
    CHECK(resumed.status == 2);
    CHECK(contains(resumed.err, expected));
    CHECK(read_text(folder / "out/trajectory.csv") == csv_before);
  };
  // Signs a changed checkpoint as the host does: the checksum of the rest, as dumped.
  const auto signed_text = [](json document) {
    document.erase("checksum");
    const std::string checksum = nonsep::host::content_hash_hex(nonsep::host::content_hash(document.dump()));
    document["checksum"] = checksum;
    return document.dump();
  };

  SUBCASE("a changed value without a matching checksum") {
    json edited = checkpoint;
    edited["records"][0]["status"] = "completed";
    write_text(checkpoint_path, edited.dump());
    resume("its content does not match its checksum");
  }
  SUBCASE("a checksum that matches, over a state that is not finite") {
    json edited = checkpoint;
    edited["active"]["q"][0] = "inf";
    write_text(checkpoint_path, signed_text(edited));
    resume("active trajectory 0 has a state that is not finite");
  }
  SUBCASE("a checksum that matches, over an active trajectory whose record says it ended") {
    json edited = checkpoint;
    edited["records"][0]["status"] = "completed";
    write_text(checkpoint_path, signed_text(edited));
    resume("trajectory 0 is active but its record says \"completed\"");
  }
  SUBCASE("bytes after a NUL, which a JSON parser would take for the end") {
    write_text(checkpoint_path, original + std::string("\0garbage{{", 10));
    resume("a NUL byte at byte offset " + std::to_string(original.size()));
  }
  SUBCASE("trajectory.csv of the recorded length with other rows (another run's)") {
    write_text(checkpoint_path, original);
    std::string csv = read_text(folder / "out/trajectory.csv");
    const auto first_row = csv.find('\n');
    REQUIRE(first_row + 1 < checkpoint["observers"]["trajectory_csv"]["bytes"].get<std::uint64_t>());
    csv[first_row + 1] = csv[first_row + 1] == '0' ? '1' : '0';  // the trajectory index of the first row
    write_text(folder / "out/trajectory.csv", csv);
    resume("are not the ones the checkpoint recorded");
  }
}

TEST_CASE("a plugin that crashes the process: its own exit status (134, 139, 3), and the rows written before whole") {
  // The trust model (docs/trust-model.md): a plugin runs inside nonsep, so its crash is nonsep's: the status is the
  // signal's 128 + n (SIGABRT 134, SIGSEGV 139) or the plugin's own exit code, and what was flushed before stays
  // readable.
#if defined(NONSEP_TEST_ADDRESS_SANITIZER)
  // The sanitized suite: ASan's handler catches SIGSEGV itself and aborts (abort_on_error=1, tests/ci), and
  // LeakSanitizer would turn exit(3) into its own status by reporting what the interrupted run still held.
  const std::pair<int, int> cases[] = {{0, 134}, {1, 134}, {2, 3}};
  const std::string sanitizer_options = std::getenv("ASAN_OPTIONS") ? std::getenv("ASAN_OPTIONS") : "";
  ::setenv("ASAN_OPTIONS", (sanitizer_options + ":detect_leaks=0").c_str(), 1);
#else
  const std::pair<int, int> cases[] = {{0, 134}, {1, 139}, {2, 3}};
#endif
  for (const auto& [how, status] : cases) {
    const int crash = how;  // clang 14 cannot capture a structured binding
    CAPTURE(crash);
    TemporaryFolder folder;
    const auto file =
        write_job(folder / "job.json", job_with("blowup", state(0.5, 0.5), {{"crash_after", 50000}, {"crash_how", how}},
                                                {{"dt", 1e-4}, {"steps", 1000000}}));
    const Result result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
    CHECK(result.status == status);
    CHECK(result.killed == (how != 2));
    const auto rows = check_complete_csv(folder / "out/trajectory.csv", 1);
    CHECK(rows.size() > 1000);  // buffers of 64 KiB were flushed before the crash, each ending on a row
    CHECK(!std::filesystem::exists(folder / "out/summary.json"));
  }
#if defined(NONSEP_TEST_ADDRESS_SANITIZER)
  ::setenv("ASAN_OPTIONS", sanitizer_options.c_str(), 1);
#endif
}

}  // namespace test_host_reliability
