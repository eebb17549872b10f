// What the output folder must withstand besides other runs (test_host_output_folder.cpp): a FIFO at any output
// name (never a hang: exit 2 at once), the folder renamed and replaced by a link mid-run (the files still go to the
// folder that was opened and locked), a dangling link given as the folder, and a lock held by some other process.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host_test_support.hpp"

namespace test_host_output_integrity {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

// paper1d from (2, 0): `steps` basic steps of 1e-5, a row every 1000 steps, into out/.
json long_job(std::uint64_t steps) {
  return {{"model", {{"plugin", "paper1d"}}},
          {"integrator", {{"scheme", "basic"}}},
          {"initial", {{"q", {2.0}}, {"p", {0.0}}}},
          {"time", {{"dt", 1e-5}, {"steps", steps}}},
          {"output", {{"directory", "out"}, {"every", 1000}}}};
}

json study_job() {
  return {{"model", {{"plugin", "paper1d"}}},
          {"initial", {{"q", {2.0}}, {"p", {0.0}}}},
          {"time", {{"t_end", 0.4}}},
          {"output", {{"directory", "out"}}},
          {"study", {{"steps", {8, 16}}, {"integrators", {{{"scheme", "basic"}}}}}}};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("a FIFO at any output name of a run or a study is exit 2 at once, naming it, for every use of the folder") {
  const std::vector<std::string> run_names{".nonsep-run.json", "summary.json", "trajectory.csv", "trajectories.csv",
                                           "checkpoint.json"};
  const std::vector<std::string> study_names{"summary.json", "convergence.csv", "work_precision.csv"};
  for (const bool study : {false, true})
    for (const std::string& name : study ? study_names : run_names)
      for (const char* flag : {"", "--force", "--resume"}) {
        if (study && std::string(flag) == "--resume") continue;  // a study is not resumed
        CAPTURE(name);
        CAPTURE(flag);
        TemporaryFolder folder;
        const auto file = write_job(folder / "job.json", study ? study_job() : long_job(1000));
        std::filesystem::create_directories(folder / "out");
        REQUIRE(::mkfifo((folder / "out" / name).c_str(), 0644) == 0);
        std::vector<std::string> args{"run", "--quiet", file.string()};
        if (*flag) args.insert(args.begin() + 2, flag);
        const auto result = finish(start_nonsep(args, folder.path()), std::chrono::seconds(20));
        INFO("stderr: " << result.err);
        CHECK(result.status == 2);
        CHECK(contains(result.err, name));
        CHECK(contains(result.err, "FIFO"));
        struct stat status {};
        CHECK((::lstat((folder / "out" / name).c_str(), &status) == 0 && S_ISFIFO(status.st_mode)));
      }
}

TEST_CASE("the output folder renamed and replaced by a link mid-run: the run's files go to the folder it locked") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", long_job(1'000'000'000));
  const Process running = start_nonsep({"run", "--quiet", file.string()}, folder.path());
  REQUIRE(wait_until([&] {
    std::error_code error;
    return std::filesystem::file_size(folder / "out" / "trajectory.csv", error) > 100 && !error;
  }));
  std::filesystem::rename(folder / "out", folder / "out.orig");
  std::filesystem::create_directories(folder / "elsewhere");
  std::filesystem::create_directory_symlink(folder / "elsewhere", folder / "out");
  REQUIRE(::kill(running.pid, SIGINT) == 0);
  const auto result = finish(running, std::chrono::seconds(30));
  INFO("stderr: " << result.err);
  CHECK(result.status == 130);
  CHECK(std::filesystem::is_empty(folder / "elsewhere"));
  for (const char* name : {"summary.json", "trajectories.csv", "checkpoint.json", "trajectory.csv"})
    CHECK(std::filesystem::exists(folder / "out.orig" / name));
  CHECK(read_json(folder / "out.orig" / "summary.json")["status"] == "interrupted");
}

TEST_CASE("a dangling link given as the output folder is named as one, exit 2") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", long_job(10));
  std::filesystem::create_directory_symlink(folder / "missing", folder / "out");
  const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(contains(result.err, "is a symbolic link to " + (folder / "missing").string() + ", which does not exist"));
  CHECK(!contains(result.err, "File exists"));
}

TEST_CASE("a lock held by another process: the message does not name the pid an earlier, ended run left") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", long_job(10));
  REQUIRE(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  const std::string ended = read_text(folder / "out" / ".nonsep.lock");
  const int lock = ::open((folder / "out" / ".nonsep.lock").c_str(), O_RDWR | O_CLOEXEC);
  REQUIRE(lock >= 0);
  REQUIRE(::flock(lock, LOCK_EX | LOCK_NB) == 0);
  const auto refused = run_nonsep({"run", "--quiet", file.string()}, folder.path());
  ::close(lock);
  INFO("stderr: " << refused.err);
  CHECK(refused.status == 2);
  CHECK(contains(refused.err, "in use by another process"));
  CHECK(!contains(refused.err, "another nonsep run"));
  CHECK(contains(refused.err, "of an earlier run, ended"));
}

}  // namespace test_host_output_integrity
