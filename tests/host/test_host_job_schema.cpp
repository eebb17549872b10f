// The generated job schema against the reader: the schema is generated from the reader's key tables, and these
// tests check that the reader really applies what the schema states (ranges, signs, defaults, required keys), so
// that a table entry the reader ignored would fail here. schemas/job.schema.json being exactly this output is
// checked by the host.schema test.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/job_schema.hpp"

namespace test_host_job_schema {

using nlohmann::json;
using namespace nonsep;
using namespace nonsep::host;

namespace {

std::vector<JobIssue> issues_of(const json& document) {
  std::vector<JobIssue> issues;
  parse_job(document, "/jobs/test.json", issues);
  return issues;
}

bool names(const std::vector<JobIssue>& issues, const std::string& path) {
  return std::any_of(issues.begin(), issues.end(), [&](const JobIssue& issue) { return issue.path == path; });
}

// A valid run with every optional section present, so that each value can be varied alone.
json full_run() {
  json job = host_testing::quickstart_job();
  job["time"] = {{"dt", 0.005}, {"steps", 10}};
  job["output"] = {{"every", 1}, {"energy_every", 0}};
  job["checkpoint"] = {{"every_steps", 0}, {"every_seconds", 60}};
  job["analysis"] = {{"closest_return_after", 0.1}, {"max_relative_energy_error", 0.5}};
  return job;
}

// The schema of the value at `pointer` of a run (following $ref into $defs once, as the generator writes them).
json property_schema(const json& schema, const std::string& section, const std::string& key) {
  json object = schema["properties"][section];
  if (section == "time") object = schema["$defs"]["run_time"];
  return object["properties"][key];
}

}  // namespace

TEST_CASE("the schema's ranges of numbers and integers are the reader's") {
  const json schema = job_schema();
  const json finite = schema["$defs"]["finite"];
  int checked = 0;
  for (const auto& [section_name, key_name] :
       std::vector<std::pair<std::string, std::string>>{{"time", "dt"},
                                                        {"time", "steps"},
                                                        {"output", "every"},
                                                        {"output", "energy_every"},
                                                        {"checkpoint", "every_steps"},
                                                        {"checkpoint", "every_seconds"},
                                                        {"analysis", "closest_return_after"},
                                                        {"analysis", "max_relative_energy_error"}}) {
    const std::string &section = section_name, &key = key_name;  // clang 14 cannot capture a structured binding
    const std::string path = "/" + section + "/" + key;
    CAPTURE(path);
    const json rule = property_schema(schema, section, key);
    REQUIRE(rule.is_object());
    const auto accepted = [&](const json& value) {
      json job = full_run();
      job[section][key] = value;
      return !names(issues_of(job), path);
    };
    CHECK(accepted(full_run()[section][key]));
    if (rule.contains("minimum") && rule.value("type", "") == "integer") {
      const auto minimum = rule["minimum"].get<std::int64_t>(), maximum = rule["maximum"].get<std::int64_t>();
      CHECK(accepted(minimum));
      CHECK_FALSE(accepted(minimum - 1));
      CHECK(accepted(maximum));
      CHECK_FALSE(accepted(json(static_cast<std::uint64_t>(maximum) + 1)));
      CHECK_FALSE(accepted(static_cast<double>(minimum) + 0.5));
      ++checked;
      continue;
    }
    REQUIRE(rule.contains("$ref"));
    CHECK_FALSE(accepted("1"));
    CHECK(accepted(finite["maximum"]));
    if (rule.value("$ref", "") == "#/$defs/nonzero") CHECK_FALSE(accepted(0.0));
    if (rule.contains("exclusiveMinimum")) {
      CHECK_FALSE(accepted(rule["exclusiveMinimum"]));
      CHECK(accepted(rule["exclusiveMinimum"].get<double>() + 1e-9));
    }
    if (rule.contains("minimum")) {
      CHECK(accepted(rule["minimum"]));
      CHECK_FALSE(accepted(rule["minimum"].get<double>() - 1e-9));
    }
    if (!rule.contains("minimum") && !rule.contains("exclusiveMinimum") && rule.value("$ref", "") == "#/$defs/finite")
      CHECK(accepted(finite["minimum"]));
    ++checked;
  }
  CHECK(checked == 8);
}

TEST_CASE("the schema's defaults are what the reader fills in, and its required keys are required") {
  const json schema = job_schema();
  std::vector<JobIssue> issues;
  const Job job = parse_job(host_testing::quickstart_job(), "/jobs/test.json", issues);
  REQUIRE(issues.empty());
  const json& properties = schema["properties"];
  CHECK(properties["output"]["properties"]["every"]["default"] == job.run().every);
  CHECK(properties["output"]["properties"]["energy_every"]["default"] == job.run().energy_every);
  CHECK(properties["checkpoint"]["properties"]["every_steps"]["default"] == job.run().checkpoint.every_steps);
  CHECK(properties["checkpoint"]["properties"]["every_seconds"]["default"] == job.run().checkpoint.every_seconds);
  CHECK(properties["hamiltonian"]["default"] == "TTV");
  CHECK(properties["hamiltonian"]["enum"] == json{"TTV", "VVT"});
  for (const std::string form : {"TTV", "VVT"}) {
    json document = host_testing::quickstart_job();
    document["hamiltonian"] = form;
    CHECK(issues_of(document).empty());
  }
  for (const auto& key : schema["required"]) {
    json document = host_testing::quickstart_job();
    document.erase(key.get<std::string>());
    CHECK(names(issues_of(document), "/" + key.get<std::string>()));
  }
  // Every key the schema allows at the top level is known to the reader, and an unknown one is refused by both.
  for (const auto& item : properties.items()) {
    const std::string key = item.key();
    json document = full_run();
    if (!document.contains(key)) document[key] = nullptr;
    const auto problems = issues_of(document);
    CHECK_FALSE(std::any_of(problems.begin(), problems.end(), [&](const JobIssue& issue) {
      return issue.path == "/" + key && issue.found.find("unknown key") != std::string::npos;
    }));
  }
  CHECK(schema["additionalProperties"] == false);
}

TEST_CASE("the schema's integrator options are the catalogue's, with its defaults") {
  const json schema = job_schema();
  const json& integrator = schema["$defs"]["integrator"];
  std::vector<std::string> names_in_schema = integrator["properties"]["scheme"]["enum"];
  // The catalogue's schemes, then "auto" (a run's integrator chosen by pilots), whose branch has its own keys.
  REQUIRE(names_in_schema.size() == scheme_catalogue().size() + 1);
  CHECK(names_in_schema.back() == "auto");
  const json& chosen = integrator["allOf"][scheme_catalogue().size()]["then"];
  CHECK(chosen["required"] == json{"tolerance"});
  CHECK(chosen["properties"]["measure"]["enum"] == json{"phase", "energy"});
  for (std::size_t i = 0; i < scheme_catalogue().size(); ++i) {
    const Scheme& scheme = scheme_catalogue()[i];
    CAPTURE(scheme.name);
    CHECK(names_in_schema[i] == scheme.name);
    const json& branch = integrator["allOf"][i];
    CHECK(branch["if"]["properties"]["scheme"]["const"] == scheme.name);
    const json& options = branch["then"]["properties"];
    CHECK(options.size() == scheme.parameters.size() + 1);
    for (const auto& parameter : scheme.parameters) {
      CAPTURE(parameter.name);
      REQUIRE(options.contains(parameter.name));
      const json& option = options[parameter.name];
      if (parameter.kind == ParameterDescription::Kind::Order) {
        CHECK(option["default"] == parameter.default_text);
        CHECK(option["examples"].size() == scheme.orders().size());
      } else {
        CHECK(option["default"].get<double>() == std::stod(parameter.default_text));
      }
    }
  }
}

TEST_CASE("no two keys of one object of a job file look like misspellings of each other") {
  // The reader names the key a misspelt one likely means (looks_like_misspelling): that must never be another
  // valid key of the same object. Two pairs are let through: /analysis's "sali" and "gali", and "fli" and "ofli", are
  // the names the literature gives these indicators (a key one letter from both is named as a misspelling of either,
  // both valid).
  std::vector<std::vector<std::string>> objects;
  const auto walk = [&](const auto& self, const nlohmann::ordered_json& node) -> void {
    if (node.is_object()) {
      if (node.contains("properties") && node["properties"].is_object()) {
        std::vector<std::string> keys;
        for (const auto& [key, value] : node["properties"].items()) keys.push_back(key);
        objects.push_back(keys);
      }
      for (const auto& [key, value] : node.items()) self(self, value);
    } else if (node.is_array()) {
      for (const auto& value : node) self(self, value);
    }
  };
  walk(walk, job_schema());
  CHECK(objects.size() > 10);
  for (const auto& keys : objects)
    for (const auto& a : keys)
      for (const auto& b : keys) {
        INFO(a, " and ", b);
        const auto pair = [&](const char* x, const char* y) { return (a == x && b == y) || (a == y && b == x); };
        const bool literature_names = pair("sali", "gali") || pair("fli", "ofli");
        if (!literature_names) CHECK_FALSE(looks_like_misspelling(a, b));
      }
}

TEST_CASE("looks_like_misspelling: letter case, one edit in short names, two in long ones, never short names") {
  CHECK(looks_like_misspelling("sheme", "scheme"));
  CHECK(looks_like_misspelling("Steps", "steps"));
  CHECK(looks_like_misspelling("DT", "dt"));
  CHECK(looks_like_misspelling("outptu", "output"));  // two edits, 6 letters
  CHECK(looks_like_misspelling("paramters", "parameters"));
  CHECK(looks_like_misspelling("step", "stop"));  // one substitution in 4 letters
  CHECK_FALSE(looks_like_misspelling("scheme", "scheme"));
  CHECK_FALSE(looks_like_misspelling("q", "p"));         // too short to guess
  CHECK_FALSE(looks_like_misspelling("dt", "t"));        // too short to guess
  CHECK_FALSE(looks_like_misspelling("every", "vary"));  // two edits, 4 letters
  CHECK_FALSE(looks_like_misspelling("model", "output"));
}

TEST_CASE("a misspelt key is named as such, both where it is unknown and where the key it means is missing") {
  json job = host_testing::quickstart_job();
  job["integrator"] = {{"sheme", "basic"}};
  const auto issues = issues_of(job);
  const auto find = [&](const std::string& path) {
    const auto it = std::find_if(issues.begin(), issues.end(), [&](const JobIssue& i) { return i.path == path; });
    REQUIRE(it != issues.end());
    return it->found;
  };
  CHECK(find("/integrator/sheme") == "the unknown key \"sheme\" (did you mean \"scheme\"?)");
  CHECK(find("/integrator/scheme") == "nothing (the key is missing; \"sheme\" is there: a misspelling of it?)");
  job = host_testing::quickstart_job();
  job.erase("output");
  job["outptu"] = json::object();
  CHECK(issues_of(job).front().found == "the unknown key \"outptu\" (did you mean \"output\"?)");
  job["output"] = json::object();
  CHECK(issues_of(job).front().found == "the unknown key \"outptu\"");  // "output" is there: not meant
  job.erase("outptu");
  job["colour"] = 1;  // nothing like any key: no guess
  CHECK(issues_of(job).front().found == "the unknown key \"colour\"");
}

TEST_CASE("a misspelt choice names the value it likely means, a value like none of them no guess") {
  const auto scheme_found = [](const json& scheme) {
    json job = host_testing::quickstart_job();
    job["integrator"] = {{"scheme", scheme}};
    const auto issues = issues_of(job);
    REQUIRE(issues.size() == 1);
    CHECK(issues.front().path == "/integrator/scheme");
    return issues.front().found;
  };
  CHECK(scheme_found("gaus") == "\"gaus\" (did you mean \"gauss\"?)");
  CHECK(scheme_found("Triplet") == "\"Triplet\" (did you mean \"triplet\"?)");
  CHECK(scheme_found("rk4") == "\"rk4\"");
  CHECK(scheme_found(4) == "4");
}

TEST_CASE("a study refuses a run's strides and time step, saying where a study's step sizes go") {
  json job = {{"model", {{"plugin", "paper1d"}}},
              {"initial", {{"q", {2.0}}, {"p", {0.0}}}},
              {"time", {{"t_end", 0.4}}},
              {"study", {{"steps", {10, 20}}, {"integrators", {{{"scheme", "basic"}}}}}}};
  CHECK(issues_of(job).empty());
  job["time"]["dt"] = 0.01;
  job["output"] = {{"every", 5}, {"energy_every", 0}, {"directory", "out"}};
  const auto issues = issues_of(job);
  REQUIRE(issues.size() == 3);
  CHECK(issues[0].path == "/time/dt");
  CHECK(issues[0].found == "0.01 in a study's /time");
  CHECK(issues[0].allowed.find("each integrator's \"steps\" or \"dt\"") != std::string::npos);
  CHECK(issues[1].path == "/output/every");
  CHECK(issues[1].found == "5 together with /study");
  CHECK(issues[1].allowed.find("convergence.csv") != std::string::npos);
  CHECK(issues[2].path == "/output/energy_every");
  job["output"] = {{"every", -1}};  // refused by the table's own rule, once
  job["time"].erase("dt");
  const auto refused = issues_of(job);
  REQUIRE(refused.size() == 1);
  CHECK(refused.front().path == "/output/every");
  CHECK(refused.front().found == "-1");
}

TEST_CASE("q and p of different lengths: the first state is named with both, a later one at the list that differs") {
  json job = host_testing::quickstart_job();
  job["initial"] = {{"q", {0.5}}, {"p", {0.0, 1.0}}};
  auto issues = issues_of(job);
  REQUIRE(issues.size() == 1);  // which of the two is wrong only the model's dimension can tell: neither is blamed
  CHECK(issues.front().path == "/initial");
  CHECK(issues.front().found == "q of 1 component and p of 2");
  CHECK(issues.front().allowed == "q and p of as many components, the dimension of the model");
  job["initial"] = json::array({{{"q", {0.5}}, {"p", {0.0}}}, {{"q", {0.5}}, {"p", {0.0, 1.0}}}});
  issues = issues_of(job);
  REQUIRE(issues.size() == 1);
  CHECK(issues.front().path == "/initial/1/p");
  CHECK(issues.front().found == "2 components");
  CHECK(issues.front().allowed == "1, as many as the first state (/initial/0) has");
  job["initial"] = json::array({{{"q", {0.5, 0.1}}, {"p", {0.0, 0.0}}}, {{"q", {0.5}}, {"p", {0.0, 1.0, 2.0}}}});
  issues = issues_of(job);
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].path == "/initial/1/q");
  CHECK(issues[0].found == "1 component");
  CHECK(issues[1].path == "/initial/1/p");
  CHECK(issues[1].found == "3 components");
  job["initial"] = {{"grid", {{"q", {1.0}}, {"p", {0.0, 0.0}}}}};
  issues = issues_of(job);
  REQUIRE(issues.size() == 1);
  CHECK(issues.front().path == "/initial/grid");
  CHECK(issues.front().found == "q of 1 axis and p of 2");
}

TEST_CASE("a value its key table refuses is reported once, with the rule's text, and read no further") {
  // Each of these is checked by its object's key table alone (key_reader.hpp): one issue at the key's path, whose
  // text says what the table allows, and nothing else about it (no second message from the section's reader).
  const std::vector<std::tuple<std::string, json, std::string>> cases{
      {"/analysis/megno", json{{"megno", 1}}, "true or false: MEGNO of the first tangent vector"},
      {"/analysis/gali", json{{"gali", 40}}, "an integer from 2 to 2n (at most 32)"},
      {"/analysis/lyapunov/every", json{{"lyapunov", {{"every", -1}}}}, "an integer >= 0: write lyapunov.csv"},
      {"/analysis/poincare/direction", json{{"poincare", {{"component", "q0"}, {"direction", "up"}}}},
       "\"+\" (normal . (q, p) - value goes from < 0 to >= 0; the default), \"-\" or \"both\""},
      {"/analysis/frequencies/spectra", json{{"frequencies", {{"spectra", 1001}}}}, "an integer from 0 to 1000"},
      {"/analysis/error_estimate", json{{"error_estimate", "yes"}}, "true or false: estimate each trajectory's"},
  };
  for (const auto& [path_text, analysis, allowed_text] : cases) {
    const std::string &path = path_text, &allowed = allowed_text;  // clang 14 cannot capture a structured binding
    CAPTURE(path);
    json job = full_run();
    job["analysis"] = analysis;
    const auto issues = issues_of(job);
    REQUIRE(issues.size() == 1);
    CHECK(issues[0].path == path);
    CHECK(issues[0].allowed.find(allowed) == 0);
  }
  // The dimension's own limit stays with the reader: paper1d has n = 1, so GALI_3 is refused there, by it.
  json job = full_run();
  job["analysis"] = {{"gali", 3}};
  const auto issues = issues_of(job);
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/analysis/gali");
  CHECK(issues[0].allowed.find("an integer from 2 to 2 (2n, at most 32)") == 0);
  // A missing required key is named with the same text.
  job = full_run();
  job["initial"] = json::parse(R"({"grid": {"q": [{"from": 0.1, "to": 0.5}], "p": [0.0]}})");
  const auto missing = issues_of(job);
  REQUIRE(missing.size() == 1);
  CHECK(missing[0].path == "/initial/grid/q/0/count");
  CHECK(missing[0].allowed.find("the number of values, an integer from 1 to ") == 0);
}

TEST_CASE("pairs of keys and lists of numbers are checked by their key tables: one issue each, at the key") {
  // A pair (key_reader.hpp): the second key of two that may not go together, the first of two of which one is
  // needed, the missing one of two that go together; a list: the item that is refused, or the whole list.
  struct Case {
    std::string path, found, allowed;
    std::function<void(json&)> change;
  };
  const json study = {{"model", {{"plugin", "paper1d"}}},
                      {"initial", {{"q", {0.5}}, {"p", {0.0}}}},
                      {"time", {{"t_end", 1.0}}},
                      {"study", {{"integrators", {{{"scheme", "basic"}, {"steps", {4, 8}}}}}}}};
  const std::vector<Case> cases{
      {"/time/steps", "10 together with /time/t_end", "exactly one of \"t_end\" (the time to end at) and \"steps\"",
       [](json& job) { job["time"]["t_end"] = 1.0; }},
      {"/time/t_end", "nothing (neither \"t_end\" nor \"steps\" is given)", "exactly one of \"t_end\"",
       [](json& job) { job["time"].erase("steps"); }},
      {"/model/formula", "{\"T\":\"p0^2/2\",\"V\":\"q0^2/2\"} together with /model/plugin", "exactly one of \"plugin\"",
       [](json& job) {
         job["model"]["formula"] = {{"T", "p0^2/2"}, {"V", "q0^2/2"}};
       }},
      {"/analysis/poincare/offset", "1 together with /analysis/poincare/value", "one of them",
       [](json& job) {
         job["analysis"]["poincare"] = {{"component", "q0"}, {"value", 0.0}, {"offset", 1}};
       }},
      {"/analysis/poincare/component", "nothing (neither \"component\" nor \"normal\" is given)", "exactly one of",
       [](json& job) {
         job["analysis"]["poincare"] = {{"value", 0.0}};
       }},
      {"/initial/grid/q/0/values/1", "\"x\"", "a finite number",
       [](json& job) {
         job["initial"] = {{"grid", {{"q", {{{"values", {0.1, "x"}}}}}, {"p", {0.0}}}}};
       }},
      {"/initial/solve_for", "nothing, while \"energy\" is given", "\"energy\" and \"solve_for\" together",
       [](json& job) {
         job["initial"] = {{"grid", {{"q", {0.1}}, {"p", {0.0}}}}, {"energy", 1.0}};
       }},
      {"/analysis/frequencies/signals/1", "0, given before", "a non-empty list of distinct degrees of freedom",
       [](json& job) {
         job["analysis"]["frequencies"] = {{"signals", {0, 0}}};
       }},
      {"/analysis/poincare/normal", "[]", "a non-empty array of finite numbers",
       [](json& job) {
         job["analysis"]["poincare"] = {{"normal", json::array()}};
       }},
  };
  const auto check_cases = [](const json& base, const std::vector<Case>& list) {
    for (const auto& c : list) {
      CAPTURE(c.path);
      json job = base;
      c.change(job);
      const auto issues = issues_of(job);
      REQUIRE(issues.size() == 1);
      CHECK(issues[0].path == c.path);
      CHECK(issues[0].found == c.found);
      CHECK(issues[0].allowed.find(c.allowed) == 0);
    }
  };
  check_cases(full_run(), cases);
  const std::vector<Case> study_cases{
      {"/study/dt", "[0.5] together with /study/steps", "either \"steps\" (step counts over t_end) or \"dt\"",
       [](json& job) { job["study"]["steps"] = {2}, job["study"]["dt"] = {0.5}; }},
      {"/study/integrators/0/dt", "[0.5] together with /study/integrators/0/steps", "either \"steps\"",
       [](json& job) { job["study"]["integrators"][0]["dt"] = {0.5}; }},
      {"/study/reference_run", "{\"scheme\":\"basic\",\"steps\":[64]} together with /study/reference",
       "either \"reference\" (the state at t_end) or \"reference_run\"",
       [](json& job) {
         job["study"]["reference"] = {{"q", {0.5}}, {"p", {0.0}}};
         job["study"]["reference_run"] = {{"scheme", "basic"}, {"steps", {64}}};
       }},
      {"/study/integrators/0/steps/1", "4, given before", "a non-empty array of distinct step counts",
       [](json& job) {
         job["study"]["integrators"][0]["steps"] = {4, 4};
       }},
      {"/study/integrators/0/label", "\"\"", "a non-empty string naming the integrator",
       [](json& job) { job["study"]["integrators"][0]["label"] = ""; }},
      {"/study/integrators/0/order", "\"x\"", "an exact fraction as a string (\"4/3\") or an integer (2): ",
       [](json& job) {
         job["study"]["integrators"][0] = {{"scheme", "triplet"}, {"order", "x"}, {"steps", {4}}};
       }},
  };
  check_cases(study, study_cases);

  // Every problem at once: the items a list's rule accepts still meet the reader's own checks.
  json job = full_run();
  job["analysis"]["frequencies"] = {{"signals", {-1, 5}}};  // paper1d: one degree of freedom
  auto issues = issues_of(job);
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].path == "/analysis/frequencies/signals/0");
  CHECK(issues[1].path == "/analysis/frequencies/signals/1");
  CHECK(issues[1].allowed.find("a degree of freedom from 0 to 0") == 0);
  job = study;
  job["study"]["integrators"][0] = {{"scheme", "basic"}, {"dt", {0, -0.1, 0.1}}};
  issues = issues_of(job);
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].path == "/study/integrators/0/dt/0");
  CHECK(issues[1].path == "/study/integrators/0/dt/1");
  CHECK(issues[1].allowed == "a non-zero step size of the same sign as /time/t_end");
  // A broken pair elsewhere in the object does not hide the steps' problems.
  job = study;
  job["study"]["dt"] = {-0.1};
  job["study"]["reference"] = {{"q", {0.5}}, {"p", {0.0}}};
  job["study"]["reference_run"] = {{"scheme", "basic"}, {"steps", {64}}};
  job["study"]["integrators"][0].erase("steps");
  issues = issues_of(job);
  CHECK(names(issues, "/study/dt/0"));
  CHECK(names(issues, "/study/reference_run"));
  // An unknown scheme is one issue per entry: no default label to clash, no steps asked for.
  job = study;
  job["study"]["integrators"] = {{{"scheme", "rk4"}, {"steps", {10}}}, {{"scheme", "rk45"}}};
  issues = issues_of(job);
  REQUIRE(issues.size() == 2);
  CHECK(issues[0].path == "/study/integrators/0/scheme");
  CHECK(issues[1].path == "/study/integrators/1/scheme");
  CHECK(issues[0].allowed.find("auto") == std::string::npos);  // a study's integrators cannot be chosen
  // A run's integrator may be "auto": its message says so.
  job = full_run();
  job["integrator"] = {{"scheme", "rk4"}};
  issues = issues_of(job);
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/integrator/scheme");
  CHECK(issues[0].allowed.ends_with("\"gauss\" or \"auto\""));
  // A list over its limit is refused from its size, in one issue, before any item is read.
  job = full_run();
  job["initial"] = {{"grid", {{"q", {{{"values", json::array_t(max_initial_states + 1, json("a"))}}}}, {"p", {0.0}}}}};
  issues = issues_of(job);
  REQUIRE(issues.size() == 1);
  CHECK(issues[0].path == "/initial/grid/q/0/values");
  CHECK(issues[0].found == "1000001 numbers");
  CHECK(issues[0].allowed == "at most 1000000 numbers");
}

TEST_CASE("scheme auto's tolerance range is its key table's, in the schema and in the reader") {
  const json schema = job_schema();
  json tolerance;
  for (const json& branch : schema["$defs"]["integrator"]["allOf"])
    if (branch["if"]["properties"]["scheme"]["const"] == "auto") tolerance = branch["then"]["properties"]["tolerance"];
  REQUIRE(tolerance.is_object());
  const double low = tolerance["minimum"].get<double>(), high = tolerance["maximum"].get<double>();
  CHECK(low == auto_tolerance_min);
  CHECK(high == auto_tolerance_max);
  for (const double value : {low, high, std::nextafter(low, 0.0), std::nextafter(high, 1.0)}) {
    CAPTURE(value);
    json job = full_run();
    job["integrator"] = {{"scheme", "auto"}, {"tolerance", value}};
    const auto issues = issues_of(job);
    const bool inside = value >= low && value <= high;
    CHECK(issues.empty() == inside);
    if (!inside) {
      REQUIRE(issues.size() == 1);
      CHECK(issues[0].path == "/integrator/tolerance");
      CHECK(issues[0].allowed.find("a number from 1e-14 to 0.1") == 0);
    }
  }
}

}  // namespace test_host_job_schema
