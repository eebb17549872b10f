// Work units and their merge (host/include/nonsep/host/cluster/): the pieces of a distributed run that need no MPI.
// The runs under mpirun are tests/cluster/check_distributed_run.py.
#include <doctest/doctest.h>

#include <atomic>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/cluster/distributed_run.hpp"
#include "nonsep/host/cluster/merge_outputs.hpp"
#include "nonsep/host/cluster/ranks.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"

namespace test_host_cluster {

using nonsep::host_testing::read_text;
using nonsep::host_testing::TemporaryFolder;
namespace host = nonsep::host;

namespace {
void write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}
}  // namespace

TEST_CASE("merge_csv: rows in key order across parts, trajectory numbers shifted, quoted cells kept whole") {
  const TemporaryFolder folder;
  write(folder / "a.csv", "trajectory,step,message\n0,0,a\n1,0,\"x, \"\"y\"\"\nz\"\n0,5,b\n");
  write(folder / "b.csv", "trajectory,step,message\n0,0,c\n0,3,d\n1,5,e\n");
  const std::vector<host::UnitFile> parts{{folder / "a.csv", 0}, {folder / "b.csv", 2}};
  const std::vector<std::string> keys{"step", "trajectory"};
  host::merge_csv(parts, folder / "out.csv", keys);
  CHECK(read_text(folder / "out.csv") ==
        "trajectory,step,message\n0,0,a\n1,0,\"x, \"\"y\"\"\nz\"\n2,0,c\n2,3,d\n0,5,b\n3,5,e\n");
  // trajectories.csv: one row per trajectory, merged by trajectory alone
  write(folder / "c.csv", "trajectory,status\n0,completed\n1,diverged\n");
  write(folder / "d.csv", "trajectory,status\n0,failed\n");
  const std::vector<host::UnitFile> tables{{folder / "c.csv", 0}, {folder / "d.csv", 2}};
  const std::vector<std::string> by_trajectory{"trajectory"};
  host::merge_csv(tables, folder / "by_trajectory.csv", by_trajectory);
  CHECK(read_text(folder / "by_trajectory.csv") == "trajectory,status\n0,completed\n1,diverged\n2,failed\n");
}

TEST_CASE("merge_csv: a part that does not fit is an OutputError naming it, and nothing is written") {
  const TemporaryFolder folder;
  write(folder / "a.csv", "trajectory,step\n0,0\n");
  write(folder / "other_header.csv", "trajectory,step,x\n0,0,1\n");
  write(folder / "bad_key.csv", "trajectory,step\n0,zero\n");
  const std::vector<std::string> keys{"step", "trajectory"};
  for (const char* name : {"other_header.csv", "bad_key.csv", "missing.csv"}) {
    CAPTURE(name);
    const std::vector<host::UnitFile> parts{{folder / "a.csv", 0}, {folder / name, 1}};
    try {
      host::merge_csv(parts, folder / "out.csv", keys);
      FAIL("no error");
    } catch (const host::OutputError& error) {
      CHECK(std::string(error.what()).find(name) != std::string::npos);
    }
    CHECK_FALSE(std::filesystem::exists(folder / "out.csv"));
  }
  const std::vector<std::string> unknown{"crossing"};
  const std::vector<host::UnitFile> parts{{folder / "a.csv", 0}};
  CHECK_THROWS_AS(host::merge_csv(parts, folder / "out.csv", unknown), host::OutputError);
}

TEST_CASE("unit_size: whole blocks, about 64 units, the same for any number of ranks") {
  CHECK(host::unit_size(1) == host::run_block_size);
  CHECK(host::unit_size(1000) == host::run_block_size);
  for (std::size_t count : {std::size_t{100000}, std::size_t{1000000}, std::size_t{12345678}}) {
    const std::size_t size = host::unit_size(count);
    CHECK(size % host::run_block_size == 0);
    CHECK((count + size - 1) / size <= 64);
    CHECK((count + size - 1) / size >= 56);
  }
}

TEST_CASE("merge_summaries: sums, the largest energy error as one process finds it, the worst status") {
  using json = nlohmann::ordered_json;
  const auto unit = [](const char* status, std::uint64_t completed, double largest, std::uint64_t at) {
    return json{{"status", status},
                {"time", {{"steps_completed", completed}}},
                {"energy", {{"largest_relative_error", {{"value", largest}, {"trajectory", at}}}}},
                {"output", {{"directory", "unit"}}},
                {"trajectories", 256},
                {"counts", {{"completed", 250}, {"diverged", 6}}},
                {"evaluations", {{"grad_T", 10}, {"grad_V", 20}}},
                {"wall_seconds", 1.0}};
  };
  const std::vector<json> units{unit("completed", 100, 0.5, 3), unit("diverged", 90, 0.5, 1),
                                unit("completed", 100, 0.25, 0)};
  const std::vector<std::size_t> firsts{0, 256, 512};
  const json merged = host::merge_summaries(units, firsts, 600, "out", 2.5);
  CHECK(merged["status"] == "diverged");
  CHECK(merged["counts"]["completed"] == 750);
  CHECK(merged["counts"]["diverged"] == 18);
  CHECK(merged["evaluations"]["grad_V"] == 60);
  CHECK(merged["time"]["steps_completed"] == 100);
  CHECK(merged["energy"]["largest_relative_error"]["trajectory"] == 3);  // a tie keeps the first
  CHECK(merged["trajectories"] == 600);
  CHECK(merged["output"]["directory"] == "out");
  CHECK(merged["wall_seconds"] == 2.5);
}

TEST_CASE("merge_summaries: the run's status by run_job's rule (interrupted, failed, diverged, inaccurate)") {
  using json = nlohmann::ordered_json;
  const auto unit = [](const char* status, std::uint64_t failed, std::uint64_t diverged, std::uint64_t inaccurate) {
    return json{{"status", status},
                {"time", {{"steps_completed", 10}}},
                {"energy", json::object()},
                {"output", {{"directory", "unit"}}},
                {"counts", {{"completed", 1}, {"diverged", diverged}, {"failed", failed}, {"inaccurate", inaccurate}}},
                {"evaluations", {{"grad_T", 1}}}};
  };
  const auto status_of = [](const std::vector<json>& units) {
    const std::vector<std::size_t> firsts(units.size(), 0);
    return host::merge_summaries(units, firsts, units.size(), "out", 1.0)["status"].get<std::string>();
  };
  CHECK(status_of({unit("completed", 0, 0, 0), unit("completed", 0, 0, 0)}) == "completed");
  CHECK(status_of({unit("completed", 0, 0, 0), unit("inaccurate", 0, 0, 2)}) == "inaccurate");
  CHECK(status_of({unit("inaccurate", 0, 0, 2), unit("diverged", 0, 1, 0)}) == "diverged");
  // A unit that failed as a whole (an output it could not write) has no failed trajectory, and still fails the run.
  CHECK(status_of({unit("diverged", 0, 1, 0), unit("failed", 0, 0, 0)}) == "failed");
  CHECK(status_of({unit("failed", 0, 0, 0), unit("interrupted", 0, 0, 0), unit("completed", 0, 0, 0)}) ==
        "interrupted");
  CHECK(status_of({unit("interrupted", 0, 0, 0), unit("failed", 1, 0, 0)}) == "interrupted");
}

TEST_CASE("a distributed run on one rank writes the files of an ordinary run, byte for byte") {
  const TemporaryFolder folder;
  const auto job = std::filesystem::path(NONSEP_SOURCE_DIR) / "tests/cluster/jobs/dynamics_grid.json";
  const host::LoadedJob loaded = host::load_job(job);
  host::RunOptions options;
  options.threads = 2;
  options.output_directory = folder / "plain";
  const host::RunOutcome plain = host::run_job(loaded, options);
  options.output_directory = folder / "units";
  const host::Ranks one;
  const host::RunOutcome units = host::run_distributed(loaded, options, one);
  CHECK(units.exit_status == plain.exit_status);
  CHECK(units.status == plain.status);
  CHECK(units.counts.inaccurate == plain.counts.inaccurate);
  CHECK(units.counts.inaccurate > 0);
  CHECK(units.steps_completed == plain.steps_completed);
  for (const char* name : {"trajectory.csv", "trajectories.csv", "poincare.csv", "lyapunov.csv"}) {
    CAPTURE(name);
    CHECK(read_text(folder / "units" / name) == read_text(folder / "plain" / name));
  }
  auto a = nonsep::host_testing::read_json(folder / "plain" / "summary.json");
  auto b = nonsep::host_testing::read_json(folder / "units" / "summary.json");
  for (auto* s : {&a, &b}) {
    s->erase("wall_seconds");
    (*s)["output"].erase("directory");
  }
  CHECK(a == b);
  CHECK_FALSE(std::filesystem::exists(folder / "units" / host::units_folder));
}

namespace {

const std::filesystem::path grid_job =
    std::filesystem::path(NONSEP_SOURCE_DIR) / "tests/cluster/jobs/dynamics_grid.json";

host::RunOptions options_for(const std::filesystem::path& out, bool resume) {
  host::RunOptions options;
  options.threads = 2;
  options.output_directory = out;
  options.resume = resume;
  return options;
}

// `loaded` run on one rank into `out` and stopped (as by SIGTERM) once units 0 and 1 are sealed.
void interrupt_after_two_units(const host::LoadedJob& loaded, const std::filesystem::path& out) {
  std::atomic<bool> stop{false};
  host::RunOptions options = options_for(out, false);
  options.stop_requested = &stop;
  std::thread watcher([&] {
    nonsep::host_testing::wait_until([&] { return std::filesystem::exists(out / "units/000001/.nonsep-unit.json"); });
    stop = true;
  });
  const host::Ranks one;
  const host::RunOutcome outcome = host::run_distributed(loaded, options, one);
  watcher.join();
  REQUIRE(outcome.exit_status == host::ExitStatus::interrupted);
}

// The message of a resume of `out` that must be refused.
std::string refused_resume(const host::LoadedJob& loaded, const std::filesystem::path& out) {
  const host::Ranks one;
  try {
    host::run_distributed(loaded, options_for(out, true), one);
  } catch (const host::RankFailure& failure) {
    return failure.what();
  }
  FAIL("the resume was not refused");
  return "";
}

void change_one_digit(const std::filesystem::path& path) {
  std::string text = read_text(path);
  const std::size_t at = text.find_first_of("123456789", text.find('\n'));
  text[at] = text[at] == '9' ? '8' : static_cast<char>(text[at] + 1);
  write(path, text);
}

}  // namespace

TEST_CASE("a distributed resume verifies every finished unit and refuses one edited, cut, swapped or of another job") {
  const TemporaryFolder folder;
  const host::LoadedJob loaded = host::load_job(grid_job);
  host::run_job(loaded, options_for(folder / "plain", false));
  interrupt_after_two_units(loaded, folder / "stopped");
  // The same job with another coupling: another job's units, sealed as units 0 and 1 of that job.
  nlohmann::json other = nonsep::host_testing::read_json(grid_job);
  other["model"]["parameters"]["coupling"] = 0.3;
  const host::LoadedJob other_loaded = host::load_job(nonsep::host_testing::write_job(folder / "other.json", other));
  interrupt_after_two_units(other_loaded, folder / "other");

  const auto copy = [&](const std::string& name) {
    std::filesystem::copy(folder / "stopped", folder / name, std::filesystem::copy_options::recursive);
    return folder / name;
  };
  const auto unit = [](const std::filesystem::path& out, const char* number) { return out / "units" / number; };
  {
    const auto out = copy("cut");
    std::filesystem::resize_file(unit(out, "000000") / "trajectory.csv",
                                 std::filesystem::file_size(unit(out, "000000") / "trajectory.csv") / 2);
    const std::string message = refused_resume(loaded, out);
    CHECK(message.find("cannot resume: work unit " + unit(out, "000000").string()) != std::string::npos);
    CHECK(message.find("trajectory.csv that is not the one it ended with") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out / "trajectory.csv"));
  }
  {
    const auto out = copy("digit");
    change_one_digit(unit(out, "000000") / "trajectories.csv");
    const std::string message = refused_resume(loaded, out);
    CAPTURE(message);
    CHECK(message.find("trajectories.csv that is not the one it ended with") != std::string::npos);
    CHECK(message.find(", other content)") != std::string::npos);
  }
  {
    const auto out = copy("swapped");
    std::filesystem::remove_all(unit(out, "000000"));
    std::filesystem::copy(unit(out, "000001"), unit(out, "000000"), std::filesystem::copy_options::recursive);
    CHECK(refused_resume(loaded, out).find("is sealed as another unit") != std::string::npos);
  }
  {
    const auto out = copy("foreign");
    std::filesystem::remove_all(unit(out, "000000"));
    std::filesystem::copy(unit(folder / "other", "000000"), unit(out, "000000"),
                          std::filesystem::copy_options::recursive);
    const std::string message = refused_resume(loaded, out);
    CHECK(message.find(unit(out, "000000").string() + " (trajectories 0 to 255) was computed by another job") !=
          std::string::npos);
    CHECK(message.find("parameters") != std::string::npos);
  }
  {  // a unit that wrote its files but died before its seal is run again, not merged unverified
    const auto out = copy("unsealed");
    change_one_digit(unit(out, "000001") / "trajectories.csv");
    std::filesystem::remove(unit(out, "000001") / ".nonsep-unit.json");
    const host::Ranks one;
    host::run_distributed(loaded, options_for(out, true), one);
    for (const char* name : {"trajectory.csv", "trajectories.csv", "poincare.csv", "lyapunov.csv"}) {
      CAPTURE(name);
      CHECK(read_text(out / name) == read_text(folder / "plain" / name));
    }
  }
}

TEST_CASE("a distributed resume follows no link at units/ or a unit, and no other run takes a unit's folder over") {
  const TemporaryFolder folder;
  const host::LoadedJob loaded = host::load_job(grid_job);
  interrupt_after_two_units(loaded, folder / "stopped");
  const auto copy = [&](const std::string& name) {
    std::filesystem::copy(folder / "stopped", folder / name, std::filesystem::copy_options::recursive);
    return folder / name;
  };
  {
    const auto out = copy("linked_units");
    std::filesystem::rename(out / "units", folder / "outside_units");
    std::filesystem::create_directory_symlink(folder / "outside_units", out / "units");
    const auto before = std::distance(std::filesystem::recursive_directory_iterator(folder / "outside_units"), {});
    CHECK(refused_resume(loaded, out).find((out / "units").string() + " is a symbolic link") != std::string::npos);
    CHECK(std::distance(std::filesystem::recursive_directory_iterator(folder / "outside_units"), {}) == before);
  }
  {
    const auto out = copy("linked_unit");
    std::filesystem::create_directories(folder / "outside_unit");
    std::filesystem::remove_all(out / "units/000003");
    std::filesystem::create_directory_symlink(folder / "outside_unit", out / "units/000003");
    CHECK(refused_resume(loaded, out).find("units/000003 is a symbolic link") != std::string::npos);
    CHECK(std::filesystem::is_empty(folder / "outside_unit"));
  }
  {
    const auto out = copy("taken_over");
    const host::LoadedJob small =
        host::load_job(std::filesystem::path(NONSEP_SOURCE_DIR) / "examples/jobs/quickstart.json");
    host::RunOptions force = options_for(out / "units/000001", false);
    force.force = true;
    CHECK_THROWS_AS(host::run_job(small, force), host::FolderInUse);
    // Without the unit's manifest the run goes ahead; the seal then refuses what it left.
    std::filesystem::remove(out / "units/000001/.nonsep-run.json");
    host::run_job(small, force);
    CHECK(refused_resume(loaded, out).find("work unit " + (out / "units/000001").string()) != std::string::npos);
  }
}

}  // namespace test_host_cluster
