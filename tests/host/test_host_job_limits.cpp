// The job reader's limits on hostile or mistaken input: nesting depth, file size, what is not a regular file, NUL
// in paths, and the number of initial values. Each limit is an issue with its JSON path (exit status 2 from the
// executable), never a crash, an exhausted machine or exit status 1.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/strict_json.hpp"

namespace test_host_job_limits {

using nlohmann::json;
using namespace nonsep::host;

namespace {

std::vector<std::string> paths(const std::vector<JobIssue>& issues) {
  std::vector<std::string> result;
  for (const auto& issue : issues) result.push_back(issue.path);
  return result;
}

// `levels` arrays within each other: "[[[...]]]".
std::string nested_arrays(std::size_t levels) { return std::string(levels, '[') + std::string(levels, ']'); }

// "/0/0/.../0", `components` times.
std::string pointer_of_zeros(std::size_t components) {
  std::string pointer;
  for (std::size_t i = 0; i < components; ++i) pointer += "/0";
  return pointer;
}

std::vector<JobIssue> issues_of_file(const std::filesystem::path& file) {
  try {
    load_job(file);
  } catch (const InvalidJob& error) {
    return error.issues();
  }
  FAIL("the job was accepted");
  return {};
}

}  // namespace

TEST_CASE("strict JSON: at most max_nesting_depth levels of objects and arrays, the first too deep one named") {
  static_assert(max_nesting_depth == 64);
  std::vector<JobIssue> issues;
  CHECK(parse_job_text(nested_arrays(max_nesting_depth), issues));
  CHECK(issues.empty());

  CHECK_FALSE(parse_job_text(nested_arrays(max_nesting_depth + 1), issues));
  REQUIRE(issues.size() == 1);
  // The document is level 1, so the array at level 65 is the 64th element down: /0 64 times.
  CHECK(issues[0].path == pointer_of_zeros(max_nesting_depth));
  CHECK(issues[0].found == "an array nested 65 levels deep");
  CHECK(issues[0].allowed.find("at most 64 levels") != std::string::npos);

  // Inside a job, the path says where: objects by key.
  json parameters = json::object();
  json* inner = &parameters;
  for (std::size_t level = 3; level <= max_nesting_depth + 1; ++level) inner = &((*inner)["a"] = json::object());
  json document = nonsep::host_testing::quickstart_job();
  document["model"]["parameters"] = parameters;
  issues.clear();
  CHECK_FALSE(parse_job_text(document.dump(), issues));
  REQUIRE(issues.size() == 1);
  std::string expected = "/model/parameters";
  for (std::size_t level = 4; level <= max_nesting_depth + 1; ++level) expected += "/a";
  CHECK(issues[0].path == expected);
  CHECK(issues[0].found == "an object nested 65 levels deep");
}

TEST_CASE("strict JSON: a 200 KB document nested 100 000 levels deep is one issue, in time and memory of its size") {
  // Before the limit, this took about 10 GB (a path string per open level) and then crashed in error formatting,
  // which recursed once per level.
  for (const char* open : {"[", "{\"k\":"}) {
    CAPTURE(open);
    std::string text;
    for (int level = 0; level < 100000; ++level) text += open;
    std::vector<JobIssue> issues;
    CHECK_FALSE(parse_job_text(text, issues));
    REQUIRE(issues.size() == 1);
    CHECK(issues[0].path.size() == 2 * max_nesting_depth);
    CHECK(issues[0].found.find("nested 65 levels deep") != std::string::npos);
  }
}

TEST_CASE("a job file larger than max_job_file_bytes is refused at \"\" with its size, before it is parsed") {
  nonsep::host_testing::TemporaryFolder folder;
  const auto file = folder / "huge.json";
  nonsep::host_testing::write_text(file, "{}");
  std::filesystem::resize_file(file, max_job_file_bytes + 1);  // sparse: no disk space used
  auto issues = issues_of_file(file);
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path.empty());
  CHECK(issues[0].found == "a file of 67108865 bytes");
  CHECK(issues[0].allowed.find("at most 67108864 bytes (64 MiB)") != std::string::npos);

  // A device that never ends is read only up to the limit.
  issues = issues_of_file("/dev/zero");
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path.empty());
  CHECK(issues[0].found == "more than 67108864 bytes at /dev/zero");
}

TEST_CASE("a directory given as the job file is named as one") {
  nonsep::host_testing::TemporaryFolder folder;
  const auto issues = issues_of_file(folder.path());
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path.empty());
  CHECK(issues[0].found == "a directory at " + folder.path().string());
}

TEST_CASE("the executable: /dev/zero and a directory as the job file are invalid input, exit status 2") {
  nonsep::host_testing::TemporaryFolder folder;
  for (const std::string& file : {std::string("/dev/zero"), folder.path().string()}) {
    CAPTURE(file);
    const auto result = nonsep::host_testing::run_nonsep({"validate", file}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("(document): found ") != std::string::npos);
    CHECK(result.err.find("unexpected") == std::string::npos);
  }
}

TEST_CASE("paths with NUL are refused: /model/plugin and /output/directory") {
  json document = nonsep::host_testing::quickstart_job();
  document["model"]["plugin"] = std::string("paper1d\0.so", 11);
  document["output"]["directory"] = std::string("out\0put", 7);
  std::vector<JobIssue> issues;
  const auto parsed = parse_job_text(document.dump(), issues);
  REQUIRE(parsed);
  const Job job = parse_job(*parsed, "/jobs/test.json", issues);
  CHECK(paths(issues) == std::vector<std::string>{"/model/plugin", "/output/directory"});
  for (const auto& issue : issues) CHECK(issue.found.find("\\u0000") != std::string::npos);
  CHECK(job.plugin.empty());
}

TEST_CASE("max_initial_values applies to every kind of initial state, not only grids") {
  // The smallest states over the limit: 2^24 + 1 numbers in q, refused from the sizes of the arrays before any is
  // copied (a grid is refused from its axes' sizes, tested with the other grid cases). The arrays are built in
  // place and p is short where its length does not matter, to keep the test's memory down (16 bytes a number).
  const auto zeros = [](std::size_t n) { return json(json::array_t(n, json(0.0))); };
  json document = nonsep::host_testing::quickstart_job();
  document["initial"] = json::object();
  document["initial"]["q"] = zeros(max_initial_values + 1);
  document["initial"]["p"] = zeros(1);
  std::vector<JobIssue> issues;
  Job job = parse_job(document, "/jobs/test.json", issues);
  REQUIRE(paths(issues) == std::vector<std::string>{"/initial/q"});
  CHECK(issues[0].found == "16777217 numbers");
  CHECK(issues[0].allowed == "at most 16777216 numbers");
  CHECK(job.initial.q.empty());

  // A list: the first state is read, the second would go over the limit.
  const std::size_t half = max_initial_values / 2 + 1;
  document["initial"] = json::array();
  for (std::size_t p_size : {half, std::size_t{1}}) {
    json state = json::object();
    state["q"] = zeros(half);
    state["p"] = zeros(p_size);
    document["initial"].push_back(std::move(state));
  }
  issues.clear();
  job = parse_job(document, "/jobs/test.json", issues);
  REQUIRE(paths(issues) == std::vector<std::string>{"/initial"});
  CHECK(issues[0].found == "2 states of dimension 8388609");
  CHECK(issues[0].allowed == "at most 16777216 numbers in q (states times dimension)");
  CHECK(job.initial.count == 1);
}

TEST_CASE("the model's size: dimension 0 is refused, and so is a dense Hessian too large to hold, before any step") {
  nonsep::host_testing::TemporaryFolder folder;
  const auto job_of = [](const std::string& plugin, std::size_t dimension) {
    return json{{"model", {{"plugin", plugin}, {"parameters", {{"dimension", dimension}}}}},
                {"integrator", {{"scheme", "basic"}}},
                {"initial", {{"q", json::array_t(dimension, json(0.5))}, {"p", json::array_t(dimension, json(0.1))}}},
                {"time", {{"dt", 1e-3}, {"steps", 2}}},
                {"output", {{"directory", "out"}, {"every", 0}}}};
  };
  const auto zero = nonsep::host_testing::write_job(folder / "zero.json", job_of("blowup", 0));
  for (const char* command : {"validate", "run"}) {
    CAPTURE(command);
    const auto result = nonsep::host_testing::run_nonsep({command, zero.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("/model/parameters") != std::string::npos);
    CHECK(result.err.find("dimension 0") != std::string::npos);
  }
  // 20000 x 20000 doubles are 3 GiB: refused at /model when the plugin has Hessians (H needs them) ...
  const auto huge = nonsep::host_testing::write_job(folder / "huge.json", job_of("blowup", 20000));
  const auto refused = nonsep::host_testing::run_nonsep({"run", "--quiet", huge.string()}, folder.path());
  CHECK(refused.status == 2);
  CHECK(refused.err.find("/model: found a model of dimension 20000, whose Hessian (for H) would take 3.0 GiB") !=
        std::string::npos);
  CHECK(!std::filesystem::exists(folder / "out" / "summary.json"));
  // ... and runs without them, when there is no energy to evaluate.
  const auto gradients_only =
      nonsep::host_testing::write_job(folder / "gradients.json", job_of("blowup_gradients_only", 20000));
  CHECK(nonsep::host_testing::run_nonsep({"run", "--quiet", gradients_only.string()}, folder.path()).status == 0);
  // A plugin with Hessian-vector products forms no matrix: the energy every step and a Lyapunov vector at n =
  // 20000.
  json lattice = job_of("lattice_chain", 20000);
  lattice["model"]["parameters"] = {{"sites", 20000}};
  lattice["output"] = {{"directory", "lattice"}, {"every", 0}, {"energy_every", 1}};
  lattice["analysis"] = {{"lyapunov", json::object()}};
  const auto products = nonsep::host_testing::write_job(folder / "lattice.json", lattice);
  const auto ran = nonsep::host_testing::run_nonsep({"run", "--quiet", products.string()}, folder.path());
  INFO(ran.err);
  CHECK(ran.status == 0);
  CHECK(std::filesystem::exists(folder / "lattice" / "summary.json"));
}

}  // namespace test_host_job_limits
