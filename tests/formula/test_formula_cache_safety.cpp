// The formula cache and the compiler under attack, through the `nonsep` executable with the stand-in compiler
// (formula_test_support.hpp): a fallback folder planted by someone else, a lock that is a link, entry files that
// are FIFOs or links to /dev/zero, a compiler that hangs (or leaves a child holding its output), a full disk while
// writing the entry, a signal during a compile, and the leftovers of a nonsep that died compiling.
#include <doctest/doctest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <fstream>
#include <sstream>

#include "address_sanitizer.hpp"
#include "formula_test_support.hpp"

namespace test_formula_cache_safety {

using namespace nonsep::host_testing;
using namespace nonsep::formula_testing;

namespace {

// Whether the process `pid` still runs (exists and is not a zombie waiting to be reaped).
bool running(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return false;
  const auto close = text.rfind(')');
  return close != std::string::npos && close + 2 < text.size() && text[close + 2] != 'Z';
}

// The process ids the stand-in compiler wrote to FAKE_PIDS.
std::vector<pid_t> logged_pids(const fs::path& file) {
  std::vector<pid_t> pids;
  std::istringstream words(fs::exists(file) ? read_text(file) : "");
  for (pid_t pid; words >> pid;) pids.push_back(pid);
  return pids;
}

bool none_running(const fs::path& file) {
  const auto pids = logged_pids(file);
  return std::none_of(pids.begin(), pids.end(), running);
}

// The names in `folder` that begin with `prefix`.
std::vector<std::string> names_with(const fs::path& folder, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code error;
  for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error))
    if (const auto name = it->path().filename().string(); name.rfind(prefix, 0) == 0) names.push_back(name);
  return names;
}

struct Setup {
  TemporaryFolder folder;
  Environment compiler{"NONSEP_CXX", write_fake_compiler(folder).string()};
  Environment log{"FAKE_LOG", (folder / "calls.log").string()};
  Environment cache{"NONSEP_CACHE_DIR", (folder / "cache").string()};
  fs::path job = write_job(folder / "job.json", job_with({{"formula", paper1d_formula("paper1d")}}));

  Result run(const std::string& output) const {
    return run_nonsep({"run", "--quiet", "-o", (folder / output).string(), job.string()}, folder.path());
  }
  // The cache key of a run's formula, from its summary.json.
  std::string key(const std::string& output) const {
    return read_json(folder / output / "summary.json")["model"]["formula"]["cache_key"].get<std::string>();
  }
};

}  // namespace

TEST_CASE("formula cache: the temporary fallback is used only when it is this user's own folder, mode 0700") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  write_text(folder / "not-a-folder", "");
  Environment unwritable("NONSEP_CACHE_DIR", (folder / "not-a-folder" / "cache").string());
  Environment temporary("TMPDIR", folder.path().string());
  const fs::path fallback = folder / ("nonsep-cache-" + std::to_string(::getuid()));

  SUBCASE("made fresh, it is private") {
    const auto result = setup.run("out");
    INFO(result.err);
    CHECK(result.status == 0);
    struct stat status = {};
    REQUIRE(::lstat(fallback.c_str(), &status) == 0);
    CHECK((status.st_mode & 0777) == 0700);
  }
  SUBCASE("writable by others, with an entry planted: refused, nothing compiled or loaded") {
    fs::create_directories(fallback / "formula");
    fs::permissions(fallback, fs::perms::all);
    const auto result = setup.run("out");
    CHECK(result.status == 2);
    CHECK(contains(result.err, "the cache folder " + fallback.string() + " is writable by others (mode 0777)"));
    CHECK(count_lines(folder / "calls.log") == 0);
  }
  SUBCASE("a symbolic link: refused, and nothing lands where it points") {
    fs::create_directory(folder / "elsewhere");
    fs::create_directory_symlink(folder / "elsewhere", fallback);
    const auto result = setup.run("out");
    CHECK(result.status == 2);
    CHECK(contains(result.err, fallback.string() + " is a symbolic link"));
    CHECK(fs::is_empty(folder / "elsewhere"));
  }
  SUBCASE("owned by another user (only testable as root)") {
    if (::geteuid() != 0) return;
    fs::create_directories(fallback / "formula");
    REQUIRE(::chown(fallback.c_str(), 65534, 65534) == 0);
    const auto result = setup.run("out");
    CHECK(result.status == 2);
    CHECK(contains(result.err, fallback.string() + " is owned by user 65534"));
  }
}

TEST_CASE("formula cache: a lock that is a link is not followed, and entry files that are FIFOs or links are rebuilt") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  REQUIRE(setup.run("first").status == 0);
  const std::string key = setup.key("first");
  const fs::path cache = folder / "cache" / "formula";
  fs::remove_all(cache / key);
  fs::remove(cache / (key + ".lock"));
  fs::create_directory(folder / "outside");
  fs::create_symlink(folder / "outside" / "created", cache / (key + ".lock"));
  const auto locked = setup.run("locked");
  INFO(locked.err);
  CHECK(locked.status == 0);
  CHECK(!fs::exists(folder / "outside" / "created"));
  CHECK(!fs::is_symlink(cache / (key + ".lock")));
  CHECK(count_lines(folder / "calls.log") == 2);

  fs::remove(cache / key / "model.cpp");
  REQUIRE(::mkfifo((cache / key / "model.cpp").c_str(), 0600) == 0);
  const auto fifo =
      finish(start_nonsep({"run", "--quiet", "-o", (folder / "fifo").string(), setup.job.string()}, folder.path()),
             std::chrono::seconds(60));
  CHECK(fifo.status == 0);
  CHECK(count_lines(folder / "calls.log") == 3);
  CHECK(fs::is_regular_file(cache / key / "model.cpp"));

  fs::remove(cache / key / "entry.json");
  fs::create_symlink("/dev/zero", cache / key / "entry.json");
  const auto zero =
      finish(start_nonsep({"run", "--quiet", "-o", (folder / "zero").string(), setup.job.string()}, folder.path()),
             std::chrono::seconds(60));
  CHECK(zero.status == 0);
  CHECK(count_lines(folder / "calls.log") == 4);
  CHECK(read_text(folder / "first" / "trajectories.csv") == read_text(folder / "zero" / "trajectories.csv"));
}

TEST_CASE("formula cache: the plugin loaded is the file checked, even when its path leads elsewhere by the load") {
#if defined(NONSEP_TEST_ADDRESS_SANITIZER)
  return;  // a preloaded library must not come before AddressSanitizer's runtime
#endif
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  REQUIRE(setup.run("first").status == 0);
  const fs::path entry = folder / "cache" / "formula" / setup.key("first") / "paper1d.so";
  const fs::path intruder = folder / "cache" / "intruder.so";
  fs::copy_file(NONSEP_TEST_INTRUDER, intruder);
  // Between the entry's check and its load, another library takes the plugin's path (swap_before_load.cpp).
  const Environment preload("LD_PRELOAD", NONSEP_TEST_SWAP_PRELOAD);
  const Environment from("NONSEP_TEST_SWAP_FROM", intruder.string());
  const Environment to("NONSEP_TEST_SWAP_TO", entry.string());
  const Environment marker("NONSEP_TEST_INTRUDER_MARKER", (folder / "intruder-ran").string());
  const auto swapped = setup.run("swapped");
  INFO(swapped.err);
  CHECK(!fs::exists(intruder));  // the swap was made
  CHECK(!fs::exists(folder / "intruder-ran"));
  CHECK(swapped.status == 0);
  CHECK(count_lines(folder / "calls.log") == 1);
}

TEST_CASE("formula cache: the compile time limit ends a hanging compiler and all its processes, exit 2") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  Environment pids("FAKE_PIDS", (folder / "pids").string());
  Environment limit("NONSEP_COMPILE_TIME_LIMIT", "1");

  SUBCASE("a compile that never ends") {
    Environment slow("FAKE_SLEEP", "1000");
    const auto result =
        finish(start_nonsep({"run", "--quiet", setup.job.string()}, folder.path()), std::chrono::seconds(60));
    CHECK(result.status == 2);
    CHECK(contains(result.err, "the compiler " + (folder / "fake-c++").string() +
                                   " did not finish within the compile time limit of 1 s (NONSEP_COMPILE_TIME_LIMIT"));
    CHECK(logged_pids(folder / "pids").size() == 2);
    CHECK(wait_until([&] { return none_running(folder / "pids"); }, std::chrono::seconds(30)));
    CHECK(names_with(folder / "cache" / "formula", ".building-").empty());
  }
  SUBCASE("a --version that never ends") {
    Environment slow("FAKE_VERSION_SLEEP", "1000");
    const auto result =
        finish(start_nonsep({"run", "--quiet", setup.job.string()}, folder.path()), std::chrono::seconds(60));
    CHECK(result.status == 2);
    CHECK(contains(result.err, "compile time limit of 1 s"));
  }
  SUBCASE("a background child holding the output: nonsep goes on when the compiler exits, and ends the child") {
    Environment limit_off("NONSEP_COMPILE_TIME_LIMIT", "600");
    Environment linger("FAKE_LINGER", "1000");
    const auto result =
        finish(start_nonsep({"run", "--quiet", setup.job.string()}, folder.path()), std::chrono::seconds(60));
    INFO(result.err);
    CHECK(result.status == 0);
    CHECK(logged_pids(folder / "pids").size() == 1);
    CHECK(wait_until([&] { return none_running(folder / "pids"); }, std::chrono::seconds(30)));
  }
  SUBCASE("an unusable limit is an error naming the variable") {
    Environment bad("NONSEP_COMPILE_TIME_LIMIT", "soon");
    const auto result = setup.run("out");
    CHECK(result.status == 2);
    CHECK(contains(result.err, "NONSEP_COMPILE_TIME_LIMIT is \"soon\""));
  }
}

TEST_CASE("formula cache: SIGINT, SIGTERM or SIGKILL during a compile leave no compiler and no build folder") {
  for (const int signal : {SIGINT, SIGTERM, SIGKILL}) {
    for (const bool model_compile : {false, true}) {
      CAPTURE(signal);
      CAPTURE(model_compile);
      Setup setup;
      const TemporaryFolder& folder = setup.folder;
      Environment pids("FAKE_PIDS", (folder / "pids").string());
      Environment slow("FAKE_SLEEP", "1000");
      fs::create_directory(folder / "plugins");
      const auto model_file = write_job(folder / "model.json", paper1d_formula("paper1d"));
      const Process process = model_compile ? start_nonsep({"model", "compile", model_file.string(), "-o",
                                                            (folder / "plugins" / "paper1d.so").string()},
                                                           folder.path())
                                            : start_nonsep({"run", "--quiet", setup.job.string()}, folder.path());
      REQUIRE(wait_until([&] { return logged_pids(folder / "pids").size() == 2; }, std::chrono::seconds(60)));
      ::kill(process.pid, signal);
      const Result result = finish(process, std::chrono::seconds(60));
      CHECK(result.status == 128 + signal);
      CHECK(wait_until([&] { return none_running(folder / "pids"); }, std::chrono::seconds(30)));
      CHECK(wait_until([&] { return names_with(folder / "cache" / "formula", ".building-").empty(); },
                       std::chrono::seconds(30)));
      CHECK(wait_until([&] { return names_with(folder / "plugins", ".nonsep-compile-").empty(); },
                       std::chrono::seconds(30)));
    }
  }
}

TEST_CASE("formula cache: a build folder left by a nonsep that died is removed by the next compile") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  const fs::path cache = folder / "cache" / "formula";
  fs::create_directories(cache / ".building-0123456789abcdef-1-2-3" / ".nonsep-compile-1-2-3");
  write_text(cache / ".building-0123456789abcdef-1-2-3" / "paper1d.so", "half");
  fs::create_directories(cache / ".stale-1-2" / "0123456789abcdef");
  const auto result = setup.run("out");
  INFO(result.err);
  CHECK(result.status == 0);
  CHECK(names_with(cache, ".building-").empty());
  CHECK(names_with(cache, ".stale-").empty());
}

TEST_CASE("formula cache: a full disk while writing the entry is said, and leaves no entry behind") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  // entry.json records the compiler's --version text: 600 lines of 100 characters make it the largest file nonsep
  // writes, so a file size limit of 60 blocks of 512 bytes (30 KiB) lets the source through and stops entry.json.
  Environment long_version("FAKE_VERSION_LINES", "600");
  const Process limited = start_process(
      {"/bin/sh", "-c", "ulimit -S -f 60 && exec \"$0\" run --quiet \"$1\"", NONSEP_EXECUTABLE, setup.job.string()},
      folder.path());
  const Result result = finish(limited);
  INFO(result.err);
  CHECK(result.status == 2);
  CHECK(contains(result.err, "cannot write " + (folder / "cache" / "formula").string()));
  CHECK(contains(result.err, "entry.json: File too large"));
  CHECK(!contains(result.err, "later runs reuse it"));
  CHECK(count_lines(folder / "calls.log") == 1);
  const fs::path cache = folder / "cache" / "formula";
  for (const auto& name : names_with(cache, "")) CHECK(name.ends_with(".lock"));
  const auto again = setup.run("out");
  INFO(again.err);
  CHECK(again.status == 0);
  CHECK(count_lines(folder / "calls.log") == 2);
  CHECK(setup.run("reused").status == 0);
  CHECK(count_lines(folder / "calls.log") == 2);
}

TEST_CASE("formula cache: run checks what validate checks before compiling anything") {
  Setup setup;
  const TemporaryFolder& folder = setup.folder;
  json wrong_dimension = job_with({{"formula", paper1d_formula("paper1d")}});
  wrong_dimension["initial"] = {{"q", {0.5, 1.0}}, {"p", {0.25, 1.0}}};
  json unknown_parameter = job_with({{"formula", paper1d_formula("paper1d")}, {"parameters", {{"alpha", 1}}}});
  json string_parameter = job_with(
      {{"formula", {{"T", "p0^2/2"}, {"V", "k*q0^2"}, {"parameters", {{"k", 1}}}}}, {"parameters", {{"k", "two"}}}});
  json both = job_with({{"plugin", "paper1d"}, {"formula", paper1d_formula("paper1d")}});
  const std::vector<std::pair<json, std::string>> cases = {{wrong_dimension, "/initial/q"},
                                                           {unknown_parameter, "/model/parameters/alpha"},
                                                           {string_parameter, "/model/parameters/k"},
                                                           {both, "/model/formula"}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    CAPTURE(i);
    const auto file = write_job(folder / ("bad" + std::to_string(i) + ".json"), cases[i].first);
    const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(contains(result.err, "  " + cases[i].second + ": found"));
    CHECK(!contains(result.err, "compiling"));
  }
  CHECK(count_lines(folder / "calls.log") == 0);
  CHECK(!fs::exists(folder / "cache" / "formula"));
}

}  // namespace test_formula_cache_safety
