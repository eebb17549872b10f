// The manuals' examples of the `nonsep` executable are what it does: README.md's first run (job, command line,
// summary.json, rows), and docs/user-guide.md's example of errors in a job file, its exit statuses and the tables
// that list the schemes.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/run/trajectory.hpp"

namespace test_host_readme {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

// The fenced code blocks of the section `heading` of the manual `file` (relative to the source tree; up to the next
// heading of the same or a higher level), each as (language, text).
std::vector<std::pair<std::string, std::string>> manual_code_blocks(const std::string& file,
                                                                    const std::string& heading) {
  const std::string readme = read_text(std::filesystem::path(NONSEP_SOURCE_DIR) / file);
  const auto start = readme.find("\n" + heading + "\n");
  REQUIRE(start != std::string::npos);
  const auto level = heading.find(' ');
  auto end = std::string::npos;
  for (std::size_t hashes = 1; hashes <= level; ++hashes) {
    std::string marker(1, '\n');  // appended, not "\n" + ...: GCC 12 warns falsely (-Wrestrict) about that
    marker.append(hashes, '#').push_back(' ');
    end = std::min(end, readme.find(marker, start + 1));
  }
  std::istringstream section(readme.substr(start, end - start));
  std::vector<std::pair<std::string, std::string>> blocks;
  std::string line;
  bool inside = false;
  while (std::getline(section, line)) {
    if (line.rfind("```", 0) == 0) {
      if (!inside) blocks.emplace_back(line.substr(3), "");
      inside = !inside;
    } else if (inside) {
      blocks.back().second += line + "\n";
    }
  }
  return blocks;
}

}  // namespace

TEST_CASE("README: the first run shows the quickstart's job, command line, summary.json and rows as they are") {
  const auto blocks = manual_code_blocks("README.md", "## A first run");
  REQUIRE(blocks.size() == 5);
  REQUIRE(blocks[0].first == "json");
  REQUIRE(blocks[1].first == "console");
  REQUIRE(blocks[2].first == "json");
  REQUIRE(blocks[3].first == "text");
  REQUIRE(blocks[4].first == "text");

  // The job: the file itself, but for the description the README shortens.
  json shown_job = json::parse(blocks[0].second);
  json job = quickstart_job();
  shown_job.erase("description");
  job.erase("description");
  CHECK(shown_job == job);

  // The command line, run from the repository root as shown.
  TemporaryFolder folder;
  const auto file = write_job(folder / "quickstart.json", quickstart_job());
  // The README's numbers are the evaluation path's (the baseline kernel's, bit for bit), which every x86-64 runs and
  // every plugin has (the wider sets round differently in the last digits, as the README says).
  ::setenv("NONSEP_INSTRUCTION_SET", "evaluation", 1);
  const auto result = run_nonsep({"run", file.string()}, folder.path());
  ::unsetenv("NONSEP_INSTRUCTION_SET");
  REQUIRE(result.status == 0);
  const std::string shown_line = blocks[1].second.substr(blocks[1].second.find('\n') + 1);
  const std::string machine_part = "results in ";
  const auto cut = shown_line.find(machine_part);
  REQUIRE(cut != std::string::npos);
  CHECK(result.out.substr(0, cut) == shown_line.substr(0, cut));

  // summary.json: everything but what depends on where, when and on which processor it ran.
  json shown = json::parse(blocks[2].second);
  json summary = read_json(folder / "quickstart.out/summary.json");
  for (json* document : {&shown, &summary}) {
    document->erase("job");
    document->erase("wall_seconds");
    document->erase("stepping");  // which instruction set the processor runs
    (*document)["model"].erase("path");
    (*document)["output"].erase("directory");
  }
  CHECK(shown == summary);

  // trajectory.csv: every row shown is a row of the file, and the first and last rows are where the README says.
  const std::string csv = read_text(folder / "quickstart.out/trajectory.csv");
  std::istringstream rows(blocks[4].second);
  std::string row;
  std::vector<std::string> shown_rows;
  while (std::getline(rows, row))
    if (row != "...") shown_rows.push_back(row);
  REQUIRE(shown_rows.size() >= 3);
  CHECK(csv.rfind(shown_rows.front() + "\n", 0) == 0);
  CHECK(csv.size() >= shown_rows.back().size() + 1);
  CHECK(csv.substr(csv.size() - shown_rows.back().size() - 1) == shown_rows.back() + "\n");
  for (const auto& shown_row : shown_rows) {
    CAPTURE(shown_row);
    CHECK(csv.find(shown_row + "\n") != std::string::npos);
  }

  // trajectories.csv (shown before trajectory.csv): as shown, whole.
  CHECK(read_text(folder / "quickstart.out/trajectories.csv") == blocks[3].second);
}

TEST_CASE("User guide: the example of errors in a job file is what `nonsep validate` prints") {
  const auto blocks = manual_code_blocks("docs/user-guide.md", "## Errors in job files");
  REQUIRE(!blocks.empty());
  REQUIRE(blocks[0].first == "console");
  const std::string& shown = blocks[0].second;
  const std::string prompt = "$ nonsep validate ";
  REQUIRE(shown.rfind(prompt, 0) == 0);
  const auto command_end = shown.find('\n');
  const std::string job = shown.substr(prompt.size(), command_end - prompt.size());
  const std::string absolute = (std::filesystem::path(NONSEP_SOURCE_DIR) / job).string();
  TemporaryFolder folder;
  auto result = run_nonsep({"validate", absolute}, folder.path());
  CHECK(result.status == 2);
  result.err.replace(result.err.find(absolute), absolute.size(), job);  // as run from the repository's root
  CHECK(result.err == shown.substr(command_end + 1));
}

TEST_CASE("User guide and --help: exit status 1 names every status with which a trajectory stops early") {
  const std::string readme = read_text(std::filesystem::path(NONSEP_SOURCE_DIR) / "docs/user-guide.md");
  const auto row = readme.find("\n| 1 | ");
  REQUIRE(row != std::string::npos);
  const std::string readme_row = readme.substr(row + 1, readme.find('\n', row + 1) - row - 1);
  TemporaryFolder folder;
  const auto help = run_nonsep({"--help"}, folder.path());
  REQUIRE(help.status == 0);
  const auto from = help.out.find("  1    ");
  REQUIRE(from != std::string::npos);
  const std::string help_entry = help.out.substr(from, help.out.find("  2    ", from) - from);
  using nonsep::host::TrajectoryStatus;
  for (const auto status : {TrajectoryStatus::diverged, TrajectoryStatus::failed, TrajectoryStatus::inaccurate}) {
    const std::string name(nonsep::host::to_string(status));
    CAPTURE(name);
    CHECK(readme_row.find(name) != std::string::npos);
    CHECK(help_entry.find(name) != std::string::npos);
  }
}

TEST_CASE("User guide: the job-key table and the schemes table name every scheme of the catalogue") {
  const std::string readme = read_text(std::filesystem::path(NONSEP_SOURCE_DIR) / "docs/user-guide.md");
  const auto row = readme.find("\n| `integrator.scheme` | ");
  REQUIRE(row != std::string::npos);
  const std::string key_row = readme.substr(row + 1, readme.find('\n', row + 1) - row - 1);
  for (const auto& scheme : nonsep::scheme_catalogue()) {
    CAPTURE(scheme.name);
    CHECK(key_row.find("`\"" + scheme.name + "\"`") != std::string::npos);
    CHECK(readme.find("\n| `" + scheme.name + "` ") != std::string::npos);  // a row of the schemes table
  }
}

}  // namespace test_host_readme
