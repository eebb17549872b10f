// `nonsep example`: starting job files that pass `nonsep validate` as written, the list of examples (the job files
// of examples/jobs and examples/paper, found beside the executable in share/nonsep), no overwriting, and the
// compiled-in quickstart job of an executable copied without its share/nonsep folder.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>

#include "host_test_support.hpp"

namespace test_host_example {

using nlohmann::json;
using namespace nonsep::host_testing;
namespace fs = std::filesystem;

namespace {

// The names of the source tree's example job files, which the build tree's share/nonsep links to.
std::set<std::string> source_examples() {
  std::set<std::string> names;
  for (const char* folder : {"examples/jobs", "examples/paper", "examples/dynamics"})
    for (const auto& entry : fs::directory_iterator(fs::path(NONSEP_SOURCE_DIR) / folder))
      if (entry.path().extension() == ".json") names.insert(entry.path().stem().string());
  return names;
}

}  // namespace

TEST_CASE("example without a name writes the quickstart job, which validates, and names the other examples") {
  TemporaryFolder folder;
  const auto result = run_nonsep({"example"}, folder.path());
  REQUIRE(result.status == 0);
  json written = json::parse(result.out);
  // "$schema" points at the schema beside the executable (in the build tree: a link to the source's schema).
  CHECK(fs::equivalent(written["$schema"].get<std::string>(),
                       fs::path(NONSEP_SOURCE_DIR) / "schemas" / "job.schema.json"));
  json expected = quickstart_job();
  written.erase("$schema");
  expected.erase("$schema");
  CHECK(written == expected);
  for (const auto& name : source_examples()) CHECK(result.err.find(name) != std::string::npos);

  write_text(folder / "start.json", result.out);
  const auto validated = run_nonsep({"validate", (folder / "start.json").string()}, folder.path());
  CHECK(validated.status == 0);
  CHECK(validated.out.find("valid: ") == 0);
}

TEST_CASE("every listed example is written with --output and passes nonsep validate, and no file is overwritten") {
  TemporaryFolder folder;
  const auto list = run_nonsep({"example", "--list"}, folder.path());
  REQUIRE(list.status == 0);
  const auto names = source_examples();
  REQUIRE(names.size() >= 3);
  for (const auto& name : names) {
    CAPTURE(name);
    CHECK(list.out.find("  " + name + " ") != std::string::npos);
    const fs::path file = folder / (name + ".json");
    const auto written = run_nonsep({"example", name, "--output", file.string()}, folder.path());
    REQUIRE(written.status == 0);
    CHECK(written.out.find("nonsep validate " + file.string()) != std::string::npos);
    const auto validated = run_nonsep({"validate", file.string()}, folder.path());
    CHECK(validated.status == 0);
    CHECK(validated.err == "");
  }
  const fs::path file = folder / "quickstart.json";
  write_text(file, "mine");
  const auto refused = run_nonsep({"example", "--output", file.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(refused.err.find(file.string() + " already exists") != std::string::npos);
  CHECK(read_text(file) == "mine");

  const auto unknown = run_nonsep({"example", "figure9"}, folder.path());
  CHECK(unknown.status == 2);
  CHECK(unknown.err.find("no example named 'figure9'; the examples are quickstart, ") != std::string::npos);
  const auto unwritable =
      run_nonsep({"example", "--output", (folder / "no" / "such" / "x.json").string()}, folder.path());
  CHECK(unwritable.status == 2);
  CHECK(unwritable.err.find("cannot write the example job to " + (folder / "no/such/x.json").string()) !=
        std::string::npos);
}

TEST_CASE("an executable copied without share/nonsep still writes the compiled-in quickstart job") {
  TemporaryFolder folder;
  fs::create_directories(folder / "bin");
  const fs::path copy = folder / "bin" / "nonsep";
  fs::copy_file(NONSEP_EXECUTABLE, copy);
  const std::string command =
      copy.string() + " example > " + (folder / "out.json").string() + " 2> " + (folder / "err.txt").string();
  REQUIRE(std::system(command.c_str()) == 0);
  const std::string source = read_text(fs::path(NONSEP_SOURCE_DIR) / "examples" / "jobs" / "quickstart.json");
  CHECK(read_text(folder / "out.json") == source);
  const std::string help = copy.string() + " --help > " + (folder / "help.txt").string();
  REQUIRE(std::system(help.c_str()) == 0);
  CHECK(read_text(folder / "help.txt")
            .find("README.md of the nonsep sources (not found beside this executable: "
                  "looked in " +
                  (folder / "share" / "nonsep").string()) != std::string::npos);
}

}  // namespace test_host_example
