// One run per output folder (output/run_folder.hpp): the lock, earlier results of another job or kind, an earlier
// run's checkpoint, stale files of the same job, planted links and orphaned temporary files, whole rows after a hard
// kill, and an output that cannot be written found before computing.
#include <doctest/doctest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "host_test_support.hpp"

namespace test_host_output_folder {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// paper1d from (q0, 0): `steps` basic steps of 1e-5, a row every `every` steps, into folder/out.
json paper1d_job(double q0, std::uint64_t steps, std::uint64_t every = 1) {
  return {{"model", {{"plugin", "paper1d"}}},
          {"integrator", {{"scheme", "basic"}}},
          {"initial", {{"q", {q0}}, {"p", {0.0}}}},
          {"time", {{"dt", 1e-5}, {"steps", steps}}},
          {"output", {{"directory", "out"}, {"every", every}}}};
}

// Waits (at most 60 s) until `condition` holds, checking every few milliseconds.
template <class Condition>
void wait_until(Condition condition, const char* what) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) FAIL("waited in vain for " << what);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

std::uintmax_t size_of(const std::filesystem::path& path) {
  std::error_code error;
  const auto size = std::filesystem::file_size(path, error);
  return error ? 0 : size;
}

}  // namespace

TEST_CASE("a second run into a folder in use is refused with the holder's pid, exit 2, and changes nothing") {
  TemporaryFolder folder;
  const auto first = write_job(folder / "a.json", paper1d_job(1.0, 1'000'000'000, 1000));
  const auto second = write_job(folder / "b.json", paper1d_job(2.0, 10));
  const Process running = start_nonsep({"run", "--quiet", first.string()}, folder.path());
  wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > 0; }, "the first run's rows");
  for (const auto& job : {second, first}) {
    const auto refused = run_nonsep({"run", "--quiet", job.string()}, folder.path());
    CHECK(refused.status == 2);
    CHECK(contains(refused.err, "is in use by another nonsep run (pid " + std::to_string(running.pid) + ")"));
  }
  ::kill(running.pid, SIGINT);
  CHECK(finish(running).status == 130);
  const auto rows = read_csv(folder / "out" / "trajectory.csv");
  for (std::size_t r = 1; r < rows.size(); ++r) CHECK(rows[r][0] == "0");  // only the first job's rows
}

TEST_CASE("another job's results are refused, --force replaces them and removes every file of the earlier run") {
  TemporaryFolder folder;
  const auto a = write_job(folder / "a.json", paper1d_job(1.0, 100));
  json b_job = paper1d_job(2.0, 50, 0);  // no trajectory.csv
  const auto b = write_job(folder / "b.json", b_job);
  REQUIRE(run_nonsep({"run", "--quiet", a.string()}, folder.path()).status == 0);
  const std::string a_summary = read_text(folder / "out" / "summary.json");
  const auto refused = run_nonsep({"run", "--quiet", b.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "holds the results of another run (" + std::filesystem::weakly_canonical(a).string()));
  CHECK(contains(refused.err, "`--force` replaces them"));
  CHECK(read_text(folder / "out" / "summary.json") == a_summary);
  CHECK(run_nonsep({"run", "--quiet", "--force", b.string()}, folder.path()).status == 0);
  CHECK(!std::filesystem::exists(folder / "out" / "trajectory.csv"));
  CHECK(read_run(folder / "out")["trajectories"][0]["final"]["step"] == 50);
  // The same job again replaces its own results without being told.
  CHECK(run_nonsep({"run", "--quiet", b.string()}, folder.path()).status == 0);
}

TEST_CASE("a study into a run's folder is refused, with --force the run's files go") {
  TemporaryFolder folder;
  const auto run = write_job(folder / "run.json", paper1d_job(1.0, 100));
  REQUIRE(run_nonsep({"run", "--quiet", run.string()}, folder.path()).status == 0);
  const json study = {{"model", {{"plugin", "paper1d"}}},
                      {"initial", {{"q", {1.0}}, {"p", {0.0}}}},
                      {"time", {{"t_end", 0.1}}},
                      {"study", {{"integrators", {{{"scheme", "basic"}}}}, {"steps", {10, 20}}}},
                      {"output", {{"directory", "out"}}}};
  const auto file = write_job(folder / "study.json", study);
  const auto refused = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "holds the results of another run"));
  CHECK(run_nonsep({"run", "--quiet", "--force", file.string()}, folder.path()).status == 0);
  CHECK(std::filesystem::exists(folder / "out" / "convergence.csv"));
  CHECK(!std::filesystem::exists(folder / "out" / "trajectory.csv"));
  CHECK(!std::filesystem::exists(folder / "out" / "trajectories.csv"));
}

TEST_CASE("a checkpoint is neither discarded nor overwritten by a plain run: --resume continues, --force starts over") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 1'000'000'000, 1000));
  const Process running = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > 0; }, "rows");
  ::kill(running.pid, SIGINT);
  REQUIRE(finish(running).status == 130);
  REQUIRE(std::filesystem::exists(folder / "out" / "checkpoint.json"));
  const std::string checkpoint = read_text(folder / "out" / "checkpoint.json");
  const auto refused = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "holds the checkpoint of an interrupted run"));
  CHECK(read_text(folder / "out" / "checkpoint.json") == checkpoint);
  const auto both = run_nonsep({"run", "--quiet", "--force", "--resume", file.string()}, folder.path());
  CHECK(both.status == 2);
  const json short_job = paper1d_job(1.0, 20);
  write_job(file, short_job);
  CHECK(run_nonsep({"run", "--quiet", "--force", file.string()}, folder.path()).status == 0);
  CHECK(!std::filesystem::exists(folder / "out" / "checkpoint.json"));
  CHECK(read_csv(folder / "out" / "trajectory.csv").size() == 22);
}

TEST_CASE("a new run of the same job that is killed leaves no summary of the earlier run beside its partial rows") {
  TemporaryFolder folder;
  json job = paper1d_job(1.0, 100);
  const auto file = write_job(folder / "job.json", job);
  REQUIRE(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  REQUIRE(std::filesystem::exists(folder / "out" / "summary.json"));
  job["time"]["steps"] = 1'000'000'000;
  write_job(file, job);
  const Process running = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > 100'000; }, "the new run's rows");
  ::kill(running.pid, SIGKILL);
  finish(running);
  CHECK(!std::filesystem::exists(folder / "out" / "summary.json"));
  CHECK(!std::filesystem::exists(folder / "out" / "trajectories.csv"));
}

// One write() per buffer ending on a row boundary, but Linux may end a write() to a file between two pages when
// SIGKILL arrives (generic_perform_write checks for a fatal signal per page), so a hard kill can leave a last line
// without its newline, cut at a page boundary. What is guaranteed, and what the reader rule of docs/outputs.md relies
// on: every line that ends in a newline is a whole row, and only the last line can lack one.
TEST_CASE("after SIGKILL every line of trajectory.csv that ends in a newline is a whole row, every time") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 1'000'000'000, 1));
  int torn = 0;
  for (int kill = 0; kill < 8; ++kill) {
    CAPTURE(kill);
    const Process running = start_nonsep({"run", "--quiet", "--force", file.string()}, folder.path());
    const std::uintmax_t target = 50'000 + 37'171 * static_cast<std::uintmax_t>(kill);  // not a buffer multiple
    wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > target; }, "rows");
    ::kill(running.pid, SIGKILL);
    finish(running);
    std::string text = read_text(folder / "out" / "trajectory.csv");
    REQUIRE(!text.empty());
    if (text.back() != '\n') {
      ++torn;
      CHECK(text.size() % 4096 == 0);  // cut where the kernel stopped copying, at a page boundary
      text.erase(text.rfind('\n') + 1);
    }
    const auto rows = parse_csv(text);
    REQUIRE(rows.size() > 1);
    for (const auto& row : rows) CHECK(row.size() == rows.front().size());
  }
  MESSAGE(torn << " of 8 kills left a last line without its newline");
}

TEST_CASE("writes stay inside the folder: a linked output is replaced, not followed, orphaned temporaries go") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 10));
  std::filesystem::create_directories(folder / "out");
  write_text(folder / "precious.txt", "keep me\n");
  std::filesystem::create_symlink(folder / "precious.txt", folder / "out" / "trajectory.csv");
  std::filesystem::create_symlink(folder / "precious.txt", folder / "out" / "summary.json");
  write_text(folder / "out" / ".summary.json.tmp-AbC123", "left by a dead run");
  const auto refused = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(refused.status == 2);  // results of unknown origin: links to elsewhere are not this job's
  CHECK(run_nonsep({"run", "--quiet", "--force", file.string()}, folder.path()).status == 0);
  CHECK(read_text(folder / "precious.txt") == "keep me\n");
  CHECK(!std::filesystem::is_symlink(folder / "out" / "trajectory.csv"));
  CHECK(!std::filesystem::is_symlink(folder / "out" / "summary.json"));
  CHECK(read_csv(folder / "out" / "trajectory.csv").size() == 12);
  CHECK(!std::filesystem::exists(folder / "out" / ".summary.json.tmp-AbC123"));
}

TEST_CASE("resume never follows a linked trajectory.csv: the link's target is neither read nor cut") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 1'000'000'000, 1000));
  const Process running = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > 0; }, "rows");
  ::kill(running.pid, SIGINT);
  REQUIRE(finish(running).status == 130);
  // The trajectory file is moved out and replaced by a link to it: a longer file elsewhere that resume would cut.
  std::filesystem::rename(folder / "out" / "trajectory.csv", folder / "elsewhere.csv");
  {
    std::ofstream append(folder / "elsewhere.csv", std::ios::binary | std::ios::app);
    append << "not nonsep's\n";
  }
  const std::string before = read_text(folder / "elsewhere.csv");
  std::filesystem::create_symlink(folder / "elsewhere.csv", folder / "out" / "trajectory.csv");
  const auto refused = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "symbolic link"));
  CHECK(read_text(folder / "elsewhere.csv") == before);
}

TEST_CASE("a full disk (a file size limit) leaves trajectory.csv ending in a whole row, and says so") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 10'000'000, 1));
  // 64 blocks of 512 bytes: the limit is hit partway through a buffer. SIGXFSZ at its default disposition, which
  // kills a process that writes past the limit: nonsep must see write() come back short and then fail with EFBIG,
  // as on a full disk, whatever its caller's disposition.
  const Process running = start_process(
      {"/bin/sh", "-c", "ulimit -f 64 && exec \"$0\" run --quiet \"$1\"", NONSEP_EXECUTABLE, file.string()},
      folder.path(), {SIGXFSZ});
  const Result result = finish(running);
  CHECK(!result.killed);
  CHECK(result.status == 1);
  CHECK(read_json(folder / "out" / "summary.json")["status"] == "failed");
  CHECK(contains(result.err, "trajectory.csv"));
  const std::string text = read_text(folder / "out" / "trajectory.csv");
  REQUIRE(text.size() > 1000);
  CHECK(text.size() <= 64 * 512);
  CHECK(text.back() == '\n');
  const auto rows = parse_csv(text);
  for (const auto& row : rows) CHECK(row.size() == rows.front().size());
}

TEST_CASE("an output that cannot be written is found before computing: exit 2 at once, nothing run") {
  TemporaryFolder folder;
  // A folder where the run's manifest cannot be put in place (a non-empty folder of that name): as a full or
  // read-only disk would, this fails the first write, which happens before the first step.
  std::filesystem::create_directories(folder / "out" / ".nonsep-run.json" / "blocked");
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 1'000'000'000'000, 0));
  const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(contains(result.err, ".nonsep-run.json"));
  CHECK(!std::filesystem::exists(folder / "out" / "summary.json"));
}

TEST_CASE("a folder in the way of summary.json is found before computing, for a fresh and a resumed run") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", paper1d_job(1.0, 1'000'000'000'000, 0));
  std::filesystem::create_directories(folder / "out" / "summary.json" / "inside");
  for (const char* flag : {"--force", "--resume"}) {
    CAPTURE(flag);
    const auto result = run_nonsep({"run", "--quiet", flag, file.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(contains(result.err, "summary.json: a folder is in the way"));
  }
  CHECK(std::filesystem::exists(folder / "out" / "summary.json" / "inside"));
}

TEST_CASE("resume refuses a checkpoint of another plugin file with the same name and version, naming the part") {
  TemporaryFolder folder;
  const auto original = folder / "paper1d.so";
  std::filesystem::copy_file(std::filesystem::path(NONSEP_SHIPPED_PLUGIN_DIR) / "paper1d.so", original);
  json job = paper1d_job(1.0, 1'000'000'000, 1000);
  job["model"]["plugin"] = original.string();
  const auto file = write_job(folder / "job.json", job);
  const Process running = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  wait_until([&] { return size_of(folder / "out" / "trajectory.csv") > 0; }, "rows");
  ::kill(running.pid, SIGINT);
  REQUIRE(finish(running).status == 130);
  {  // The same library with one more byte at its end still loads, under the same name and version.
    std::ofstream append(original, std::ios::binary | std::ios::app);
    append << '\0';
  }
  const auto refused = run_nonsep({"run", "--quiet", "--resume", file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "belongs to a different job: its plugin differs"));
}

}  // namespace test_host_output_folder
