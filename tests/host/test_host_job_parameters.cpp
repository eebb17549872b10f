// /model/parameters against a plugin's metadata (pass 3 of the job reader), and the one rule for a parameter value
// that the job reader, the plugin loader and the SDK share (nonsep/sdk/parameters.hpp).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/sdk/parameter_rules.hpp"

namespace test_host_job_parameters {

using nlohmann::json;
using namespace nonsep::host;

namespace {

std::vector<std::string> paths(const std::vector<JobIssue>& issues) {
  std::vector<std::string> result;
  for (const auto& issue : issues) result.push_back(issue.path);
  return result;
}

std::vector<PluginParameter> declared_parameters() {
  std::vector<PluginParameter> declared(3);
  declared[0].name = "dimension";
  declared[0].type = "integer";
  declared[0].minimum = 1;
  declared[0].maximum = 16;
  declared[1].name = "mass";
  declared[1].type = "number";
  declared[1].minimum = 0;
  declared[1].unit = "kg";
  declared[2].name = "damped";
  declared[2].type = "boolean";
  return declared;
}

}  // namespace

TEST_CASE("model parameters are checked against the plugin's metadata") {
  const auto declared = declared_parameters();
  std::vector<JobIssue> issues;
  check_model_parameters({{"dimension", 3}, {"mass", 2.5}, {"damped", true}}, declared, issues);
  CHECK(issues.empty());

  check_model_parameters({{"dimension", 2.5}, {"mass", -1}, {"damped", 1}, {"colour", 1}, {"a/b", 1}}, declared,
                         issues);
  CHECK(paths(issues) == std::vector<std::string>{"/model/parameters/a~1b", "/model/parameters/colour",
                                                  "/model/parameters/damped", "/model/parameters/dimension",
                                                  "/model/parameters/mass"});
  CHECK(issues[3].allowed.rfind("an integer >= 1 and <= 16", 0) == 0);
  CHECK(issues[4].allowed.find(">= 0") != std::string::npos);
  CHECK(issues[4].allowed.find("kg") != std::string::npos);

  issues.clear();
  check_model_parameters({{"dimension", 17}}, declared, issues);
  CHECK(paths(issues) == std::vector<std::string>{"/model/parameters/dimension"});
  CHECK(issues[0].allowed.find("<= 16") != std::string::npos);
}

TEST_CASE("one rule for a parameter value: the job reader refuses exactly what the SDK and the loader refuse") {
  // An integer is a number with an integral value (2.0 counts, as in JSON Schema) of magnitude at most 2^53;
  // a number is finite; a boolean is true or false; bounds are inclusive. Before, the job reader refused
  // "dimension": 2.0, which the plugin itself accepted.
  const auto declared = declared_parameters();
  struct Case {
    const char* name;
    json value;
    bool accepted;
  };
  const Case cases[] = {
      {"dimension", 2, true},     {"dimension", 2.0, true},
      {"dimension", 16.0, true},  {"dimension", 1e0, true},
      {"dimension", 2.5, false},  {"dimension", 17, false},
      {"dimension", 0.0, false},  {"dimension", "2", false},
      {"dimension", true, false}, {"mass", 0, true},
      {"mass", -0.0, true},       {"mass", 1e300, true},
      {"mass", -1e-300, false},   {"mass", std::numeric_limits<double>::infinity(), false},
      {"mass", nullptr, false},   {"damped", false, true},
      {"damped", 0, false},
  };
  for (const auto& c : cases) {
    CAPTURE(c.name);
    CAPTURE(c.value.dump());
    std::vector<JobIssue> issues;
    check_model_parameters(json{{c.name, c.value}}, declared, issues);
    CHECK(issues.empty() == c.accepted);
    const auto& row =
        *std::find_if(declared.begin(), declared.end(), [&](const PluginParameter& p) { return p.name == c.name; });
    CHECK(nonsep::sdk::check_parameter_value(row.name, row.type, row.minimum, row.maximum, c.value).empty() ==
          c.accepted);
  }

  // Beyond 2^53 a double, which is how a plugin receives an integer, no longer holds every integer.
  PluginParameter unbounded;
  unbounded.name = "count";
  unbounded.type = "integer";
  for (const json& value :
       {json(9007199254740992.0), json(std::int64_t{9007199254740992}), json(-9007199254740992.0)}) {
    std::vector<JobIssue> issues;
    check_model_parameters(json{{"count", value}}, {unbounded}, issues);
    CHECK(issues.empty());
  }
  for (const json& value : {json(9007199254740994.0), json(std::int64_t{9007199254740993}),
                            json(std::uint64_t{18446744073709551615U}), json(1e300)}) {
    CAPTURE(value.dump());
    std::vector<JobIssue> issues;
    check_model_parameters(json{{"count", value}}, {unbounded}, issues);
    CHECK(paths(issues) == std::vector<std::string>{"/model/parameters/count"});
    CHECK_FALSE(nonsep::sdk::check_parameter_value("count", "integer", {}, {}, value).empty());
  }
}

TEST_CASE("a job with \"dimension\": 2.0 loads: the plugin and the reader agree on what an integer is") {
  nonsep::host_testing::TemporaryFolder folder;
  json document = nonsep::host_testing::quickstart_job();
  document["model"] = {{"plugin", "radial"}, {"parameters", {{"dimension", 2.0}}}};
  document["initial"] = {{"q", {1.0, 0.0}}, {"p", {0.5, 0.5}}};
  const LoadedJob loaded = load_job(nonsep::host_testing::write_job(folder / "job.json", document));
  CHECK(loaded.model.dimension() == 2);
  CHECK(loaded.model.parameters()["dimension"] == 2.0);
}

TEST_CASE("a sweep of one value says each trajectory's parameter set, as a sweep of several does") {
  nonsep::host_testing::TemporaryFolder folder;
  json document = nonsep::host_testing::quickstart_job();
  document["model"] = {{"plugin", "paper2d"}, {"parameters", {{"coupling", {0.2}}}}};
  document["initial"] = {{"q", {0.5, 0.1}}, {"p", {0.2, -0.1}}};
  const LoadedJob one = load_job(nonsep::host_testing::write_job(folder / "one.json", document));
  CHECK(one.job.initial.parameter_set == std::vector<std::size_t>{0});
  document["model"]["parameters"]["coupling"] = {0.1, 0.2};
  const LoadedJob two = load_job(nonsep::host_testing::write_job(folder / "two.json", document));
  CHECK(two.job.initial.parameter_set == std::vector<std::size_t>{0, 1});
}

TEST_CASE("a sweep that changes the model's dimension is refused at the swept key, naming the set") {
  nonsep::host_testing::TemporaryFolder folder;
  json document = nonsep::host_testing::quickstart_job();
  document["model"] = {{"plugin", "radial"}, {"parameters", {{"dimension", {2, 3}}}}};
  document["initial"] = {{"q", {1.0, 0.0}}, {"p", {0.5, 0.5}}};
  for (const bool shell : {false, true}) {
    if (shell)
      document["initial"] = {{"grid", {{"q", {1.0, 0.0}}, {"p", {0.5, 0.5}}}}, {"energy", 5.0}, {"solve_for", "p0"}};
    std::vector<JobIssue> issues;
    auto job = read_job(nonsep::host_testing::write_job(folder / "job.json", document), issues);
    REQUIRE(job);
    REQUIRE(issues.empty());
    CHECK_FALSE(load_model(std::move(*job), issues));
    REQUIRE(paths(issues) == std::vector<std::string>{"/model/parameters/dimension"});
    CHECK(issues[0].found.find("(set 1 of the sweep), whose model has dimension 3 where set 0") != std::string::npos);
  }
}

}  // namespace test_host_job_parameters
