// Formula models through the `nonsep` executable: malformed formulas exit 2 with a column pointer from
// `nonsep validate` (which compiles nothing); a formula model compiled by the real compiler gives the states of the
// hand-written paper1d plugin; a cached plugin's kernel sets, unpinned and pinned; the cache's mechanics with a
// stand-in compiler that copies the shipped paper1d.so (reuse, two runs compiling at once, a damaged entry, an
// unwritable cache, no compiler, a failing compiler); `nonsep model compile`.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "formula_test_support.hpp"
#include "malformed_formulas.hpp"

namespace test_formula_commands {

using nlohmann::json;
using namespace nonsep::host_testing;
using namespace nonsep::formula_testing;
namespace fs = std::filesystem;

TEST_CASE("formula commands: each malformed formula exits 2 from validate, quoting it with a caret at its column") {
  TemporaryFolder folder;
  Environment no_compiler("NONSEP_CXX", "/nonexistent/c++");
  for (std::size_t i = 0; i < malformed_formulas.size(); ++i) {
    const auto& text = malformed_formulas[i].text;  // named, not bound: clang 14 cannot capture a binding
    const auto column = malformed_formulas[i].column;
    json model = {{"formula", {{"T", "p0^2/2"}, {"V", text}, {"parameters", {{"lambda", 1}, {"k", 2}}}}}};
    const auto file = write_job(folder / ("bad" + std::to_string(i) + ".json"), job_with(model));
    const auto result = run_nonsep({"validate", file.string()}, folder.path());
    INFO("formula: " << text << "\nstderr: " << result.err);
    CHECK(result.status == 2);
    CHECK(contains(result.err, "/model/formula/V"));
    CHECK(contains(result.err, "at column " + std::to_string(column)));
    CHECK(contains(result.err, "\n" + std::string(6 + column - 1, ' ') + "^"));
  }
}

TEST_CASE("formula commands: validate checks a formula job's parameters and dimension without compiling") {
  TemporaryFolder folder;
  Environment no_compiler("NONSEP_CXX", "/nonexistent/c++");
  json good = job_with({{"formula", paper1d_formula("paper1d")}});
  const auto valid = run_nonsep({"validate", write_job(folder / "good.json", good).string()}, folder.path());
  INFO(valid.err);
  CHECK(valid.status == 0);
  CHECK(contains(valid.out, "T = p0 + p0^3/6"));
  json wrong = job_with({{"formula", paper1d_formula("paper1d")}, {"parameters", {{"alpha", 1}}}});
  wrong["initial"] = {{"q", {0.5, 1.0}}, {"p", {0.25, 1.0}}};
  const auto invalid = run_nonsep({"validate", write_job(folder / "wrong.json", wrong).string()}, folder.path());
  CHECK(invalid.status == 2);
  CHECK(contains(invalid.err, "/model/parameters/alpha"));
  CHECK(contains(invalid.err, "/initial"));
  json both = job_with({{"plugin", "paper1d"}, {"formula", paper1d_formula("paper1d")}});
  CHECK(run_nonsep({"validate", write_job(folder / "both.json", both).string()}, folder.path()).status == 2);
  const auto run = run_nonsep({"run", "--quiet", write_job(folder / "run.json", good).string()}, folder.path());
  CHECK(run.status == 2);
  CHECK(contains(run.err, "no C++ compiler"));
  CHECK(contains(run.err, "apt-get install g++"));
}

TEST_CASE("formula commands: a parameter's range is declared by its plugin and refuses values and sweeps outside it") {
  TemporaryFolder folder;
  Environment no_compiler("NONSEP_CXX", "/nonexistent/c++");
  // paper2d written as formulas, its coupling kept where the energy shells are compact as the plugin keeps it.
  const json range = {{"value", 0.2}, {"min", -0.1}, {"max", 0.3}};
  const json formula = {{"name", "coupled_2d"},
                        {"T", "p0 + p1 + (p0^3 + p1^3)/6"},
                        {"V", "(q0^2 + q1^2)/2 + (q0^2 + q1^2)^2/12 + coupling*q0^2*q1^2"},
                        {"parameters", {{"coupling", range}}}};
  const auto validate = [&](const json& model, const std::string& name) {
    json job = job_with(model);
    job["initial"] = {{"q", {0.25, 0.3}}, {"p", {-1.5, 0.2}}};
    return run_nonsep({"validate", write_job(folder / (name + ".json"), job).string()}, folder.path());
  };
  const std::string refused = "found 0.6; allowed: a value >= -0.1 and <= 0.3: ";
  SUBCASE("inside the range, a value and a sweep are accepted; outside, refused as the plugin refuses them") {
    CHECK(validate({{"formula", formula}, {"parameters", {{"coupling", 0.25}}}}, "inside").status == 0);
    CHECK(validate({{"formula", formula}, {"parameters", {{"coupling", {-0.1, 0.3}}}}}, "sweep_inside").status == 0);
    const auto value = validate({{"formula", formula}, {"parameters", {{"coupling", 0.6}}}}, "outside");
    CHECK(value.status == 2);
    CHECK(contains(value.err, "/model/parameters/coupling: " + refused + "a parameter of the formulas"));
    const auto plugin = validate({{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.6}}}}, "plugin");
    CHECK(plugin.status == 2);
    CHECK(contains(plugin.err, "/model/parameters/coupling: " + refused));
    const auto sweep = validate({{"formula", formula}, {"parameters", {{"coupling", {0.1, 0.2, 0.6}}}}}, "sweep");
    CHECK(sweep.status == 2);
    CHECK(
        contains(sweep.err, "/model/parameters/coupling/2: found the value 0.6; allowed: a value >= -0.1 and <= 0.3"));
  }
  SUBCASE("the plugin's source declares the range; a plain number has none") {
    json model = formula;
    model["parameters"]["other"] = 1.5;
    model["V"] = "(q0^2 + q1^2)/2 + (q0^2 + q1^2)^2/12 + coupling*q0^2*q1^2 + other*q0";
    write_text(folder / "model.json", model.dump());
    const auto source =
        run_nonsep({"model", "compile", (folder / "model.json").string(), "--print-source"}, folder.path());
    CHECK(source.status == 0);
    CHECK(contains(source.out,
                   "{.name = \"coupling\", .type = nonsep::sdk::ParameterType::number, .default_value = "
                   "0.2, .minimum = -0.1, .maximum = 0.3,"));
    CHECK(contains(source.out,
                   "{.name = \"other\", .type = nonsep::sdk::ParameterType::number, .default_value = "
                   "1.5, .description"));
  }
  SUBCASE("a bad range is refused at its key path, exit 2") {
    // The pair is named, not bound: clang 14 (the sanitized build) refuses a lambda's (CAPTURE's) reference to a
    // structured binding.
    for (const auto& bad_and_path : std::vector<std::pair<json, std::string>>{
             {{{"value", 0.2}, {"min", 0.3}, {"max", -0.1}}, "/coupling/min: found min 0.3 above max -0.1"},
             {{{"value", 0.6}, {"min", -0.1}, {"max", 0.3}}, "/coupling/value: found the default 0.6"},
             {{{"value", 0.2}, {"max", "0.3"}}, "/coupling/max"},
             {{{"value", 0.2}, {"max", nullptr}}, "/coupling/max"},
             {{{"min", -0.1}}, "/coupling/value"},
             {{{"value", 0.2}, {"minimum", -0.1}}, "/coupling/minimum"}}) {
      const json& bad = bad_and_path.first;
      const std::string& path = bad_and_path.second;
      json model = formula;
      model["parameters"]["coupling"] = bad;
      const auto result = validate({{"formula", model}}, "bad");
      CAPTURE(bad.dump());
      CHECK(result.status == 2);
      CHECK(contains(result.err, "/model/formula/parameters" + path));
    }
  }
}

TEST_CASE(
    "formula commands: validate says what scheme auto would try for a formula job, as for the plugin of its model") {
  TemporaryFolder folder;
  Environment no_compiler("NONSEP_CXX", "/nonexistent/c++");  // nothing is compiled
  const json automatic = {{"scheme", "auto"}, {"tolerance", 1e-6}};
  // The line after "integrator:" of `nonsep validate` for `model` with the states `initial`.
  const auto auto_line = [&](const json& model, const json& initial, const std::string& name) {
    json job = job_with(model, automatic);
    job["initial"] = initial;
    const auto result = run_nonsep({"validate", write_job(folder / (name + ".json"), job).string()}, folder.path());
    INFO(name << ": " << result.err);
    CHECK(result.status == 0);
    const auto at = result.out.find("integrator:  ");
    return at == std::string::npos ? std::string() : result.out.substr(at, result.out.find('\n', at) - at);
  };
  const json two = {{{"q", {0.25, 0.3}}, {"p", {-1.5, 0.2}}}, {{"q", {-0.75, 0.3}}, {"p", {-1.5, 0.2}}}};
  const json paper2d_formula = {{"T", "p0 + p1 + (p0^3 + p1^3)/6"},
                                {"V", "(q0^2 + q1^2)/2 + (q0^2 + q1^2)^2/12 + coupling*q0^2*q1^2"},
                                {"parameters", {{"coupling", 0.2}}}};
  const std::string product = auto_line({{"formula", paper2d_formula}}, two, "product");
  CHECK(contains(product, "scheme auto: tolerance 1e-06"));
  CHECK(contains(
      product,
      "would try gauss 16, gauss 8, gauss 6, gauss 4, mpe 4, triplet 8/3, triplet 2 with pilot runs of 2 state(s)"));
  CHECK(product == auto_line({{"plugin", "paper2d"}}, two, "paper2d"));
  // On an energy shell, before the compiled model places the states, the pilot states are an upper bound.
  const json shell = {{"grid", {{"q", {{{"from", -2.0}, {"to", 2.0}, {"count", 11}}, 0.0}}, {"p", {0.0, 0.0}}}},
                      {"energy", 7.0},
                      {"solve_for", "p1"}};
  CHECK(contains(auto_line({{"formula", paper2d_formula}}, shell, "shell"), "pilot runs of at most 8 state(s)"));
  // Given by H: the schemes that integrate H, as for the Henon-Heiles plugin (also given by H).
  const json henon_heiles = {{"H", "(p0^2 + p1^2)/2 + (q0^2 + q1^2)/2 + lambda*(q0^2*q1 - q1^3/3)"},
                             {"parameters", {{"lambda", 1}}}};
  const json one = {{{"q", {0.0, 0.1}}, {"p", {0.3, 0.0}}}};
  const std::string general = auto_line({{"formula", henon_heiles}}, one, "general");
  CHECK(contains(general, "would try gauss 16, gauss 8, gauss 6, gauss 4 with"));
  CHECK(general == auto_line({{"plugin", "henon_heiles"}}, one, "henon_heiles"));
}

TEST_CASE("formula commands: a model written with q1 and q2 for two coordinates is told that components count from 0") {
  TemporaryFolder folder;
  Environment no_compiler("NONSEP_CXX", "/nonexistent/c++");
  json job = job_with({{"formula", {{"T", "p1^2/2 + p2^2/2"}, {"V", "q1^2/2 + q2^2/2 + q1^2 * q2^2"}}}});
  job["initial"] = {{"q", {0.5, 0.25}}, {"p", {0.0, 0.1}}};
  const auto result = run_nonsep({"validate", write_job(folder / "job.json", job).string()}, folder.path());
  INFO(result.err);
  CHECK(result.status == 2);
  CHECK(contains(result.err, "/initial/q: found 2 components"));
  CHECK(contains(result.err, "3, the dimension of the model"));
  CHECK(contains(result.err, "the largest index its formulas use plus one"));
  CHECK(contains(result.err, "components count from 0, q0 .. q2"));
}

TEST_CASE(
    "formula commands: a compiled formula model gives the hand-written plugin's states, and the cache is reused") {
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const json formula_job = job_with({{"formula", paper1d_formula("paper1d_formula")}});
  const auto formula_file = write_job(folder / "formula.json", formula_job);
  // The compile takes seconds on an idle machine and minutes on a loaded one: a generous limit, not a timing.
  const auto first =
      finish(start_nonsep({"run", "--quiet", "-o", (folder / "first").string(), formula_file.string()}, folder.path()),
             std::chrono::seconds(900));
  INFO("stderr: " << first.err);
  REQUIRE(first.status == 0);
  CHECK(contains(first.err, "compiling the formula model 'paper1d_formula'"));
  CHECK(contains(first.err, "compiled in "));
  const auto second =
      run_nonsep({"run", "--quiet", "-o", (folder / "second").string(), formula_file.string()}, folder.path());
  CHECK(second.status == 0);
  CHECK(!contains(second.err, "compiling"));
  CHECK(read_text(folder / "first" / "trajectories.csv") == read_text(folder / "second" / "trajectories.csv"));

  const json by_formula = check_final_states_match_paper1d(folder, folder / "first", 1e-13);
  const json record = by_formula["model"]["formula"];
  CHECK(record["T"] == "p0 + p0^3/6");
  CHECK(record["V"] == "q0^2/2 + q0^4/12");
  CHECK(record["cache_key"].get<std::string>().size() == 16);
  CHECK(fs::exists(folder / "cache" / "formula" / record["cache_key"].get<std::string>() / "paper1d_formula.so"));
}

TEST_CASE("formula commands: paper1d written as one H gives the product-form plugin's states with gauss 3 stages") {
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const json gauss = {{"scheme", "gauss"}, {"stages", 3}};
  const json formula_job = job_with({{"formula", paper1d_hamiltonian_formula("paper1d_h")}}, gauss);
  // A Chin scheme is refused by validate and by run before anything is compiled.
  const auto chin_file = write_job(folder / "chin.json", job_with(formula_job["model"]));
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"validate"}, std::vector<std::string>{"run", "--quiet"}}) {
    std::vector<std::string> arguments = command;
    arguments.push_back(chin_file.string());
    const auto refused = run_nonsep(arguments, folder.path());
    INFO(command[0] << " stderr: " << refused.err);
    CHECK(refused.status == 2);
    CHECK(contains(refused.err, "/integrator/scheme: found \"triplet\""));
    CHECK(contains(refused.err, "need H in product form"));
    CHECK(!contains(refused.err, "compiling"));
  }
  CHECK(!fs::exists(folder / "cache" / "formula"));
  const auto formula_file = write_job(folder / "formula.json", formula_job);
  const auto validated = run_nonsep({"validate", formula_file.string()}, folder.path());
  CHECK(validated.status == 0);
  CHECK(contains(validated.out, "H = (1 + p0^2/2)^2*(1 + q0^2)"));
  // The compile takes seconds on an idle machine and minutes on a loaded one: a generous limit, not a timing.
  const auto run =
      finish(start_nonsep({"run", "--quiet", "-o", (folder / "first").string(), formula_file.string()}, folder.path()),
             std::chrono::seconds(900));
  INFO("stderr: " << run.err);
  REQUIRE(run.status == 0);
  // The same method on the same H, evaluated in another order: equal to round-off over 300 steps.
  const json by_formula = check_final_states_match_paper1d(folder, folder / "first", 1e-13, gauss);
  const json record = by_formula["model"]["formula"];
  CHECK(record["H"] == "(1 + p0^2/2)^2*(1 + q0^2)");
  CHECK(record["T"].is_null());
  CHECK(by_formula["hamiltonian"] == "general");
  const std::string key = record["cache_key"].get<std::string>();
  const json entry = json::parse(read_text(folder / "cache" / "formula" / key / "entry.json"));
  CHECK(entry["H"] == record["H"]);
  // The gradient is written from the tree (grad_H), the Hessian-vector products differentiate H; both checked.
  const auto check =
      run_nonsep({"inspect", (folder / "cache" / "formula" / key / "paper1d_h.so").string(), "--check"}, folder.path());
  INFO("inspect: " << check.out << check.err);
  CHECK(check.status == 0);
  CHECK(contains(check.out, "derivative check passed"));
}

TEST_CASE(
    "formula commands: a cached plugin has the kernel set the host uses here, and pinned to x86-64 one of its own") {
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const auto file = write_job(folder / "job.json", job_with({{"formula", paper1d_formula("paper1d_k")}}));
  const auto run = [&](const std::string& name, const std::string& pin) {
    Environment set("NONSEP_INSTRUCTION_SET", pin);  // "" as unset
    // Compiles take seconds on an idle machine and minutes on a loaded one: a generous limit, not a timing.
    const auto ran =
        finish(start_nonsep({"run", "--quiet", "-o", (folder / name).string(), file.string()}, folder.path()),
               std::chrono::seconds(900));
    INFO(name << " stderr: " << ran.err);
    REQUIRE(ran.status == 0);
    return json::parse(read_text(folder / name / "summary.json"));
  };
  // Unpinned: the plugin carries the set its runs use and, when that is a wider one, not the baseline, which the
  // host would never take on this machine.
  const json chosen = run("chosen", "")["stepping"];
  REQUIRE(chosen["path"] == "kernel");
  CHECK(chosen["plugin_kernels"] == json::array({chosen["instruction_set"]}));
  // Pinned to the baseline: another cache entry (the flags are part of its key), with the baseline kernel, whose
  // steps are the evaluation path's bit for bit.
  const json baseline = run("baseline", "x86-64")["stepping"];
  CHECK(baseline["instruction_set"] == "x86-64");
  CHECK(baseline["plugin_kernels"][0] == "x86-64");
  run("evaluation", "evaluation");
  CHECK(read_text(folder / "baseline" / "trajectories.csv") == read_text(folder / "evaluation" / "trajectories.csv"));
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(folder / "cache" / "formula")) entries += entry.is_directory();
  // Two entries when the first took a wider set (with clang, which compiles the baseline alone, the flags and so
  // the entries differ too).
  CHECK(entries >= 1u);
  if (chosen["instruction_set"] != "x86-64") CHECK(entries == 2u);
}

TEST_CASE("formula commands: every function compiles, and the gradients written from the trees pass the check") {
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const json model = {
      {"name", "every_function"},
      {"parameters", {{"lambda", 0.5}}},
      {"T",
       "p0^2/2 + p1^2/2 + lambda*cosh(p0)*sqrt(1 + p1^2) + abs(p0 - 7) + max(p1, -5) + min(p0, 9) + "
       "hypot(p0, 1) + pow(2, p1/10) + atan(p0)"},
      {"V",
       "q0^2/2 + q1^4/4 + exp(-q0^2) * sin(q1) + log(2 + q0^2) + log1p(q1^2) + cbrt(3 + q0) + erf(q1) + "
       "tanh(q0) + asinh(q1) + acosh(2 + q0^2) + atanh(q1/10) + atan2(q1, 3) + tan(q0/10) + expm1(q1/4) + "
       "square(q0) + cube(q1/3) + sinh(q0/3) + cos(q1) + asin(q0/10) + acos(q1/10) + pow(2 + q1^2, q0/5) + "
       "q0^-2 * 0.01 / (1 + q0^-2)"},
      {"K", "p0^4/40 + sin(p1)"},
      {"U", "q1^2/10 * cosh(q0/5)"}};
  const fs::path model_file = folder / "every_function.json";
  write_text(model_file, model.dump());
  // The compile takes seconds on an idle machine and minutes on a loaded one: a generous limit, not a timing.
  const auto compiled =
      finish(start_nonsep({"model", "compile", model_file.string(), "-o", (folder / "every_function.so").string()},
                          folder.path()),
             std::chrono::seconds(900));
  INFO("stderr: " << compiled.err);
  REQUIRE(compiled.status == 0);
  const auto check = run_nonsep({"inspect", (folder / "every_function.so").string(), "--check"}, folder.path());
  INFO("stdout: " << check.out << "\nstderr: " << check.err);
  CHECK(check.status == 0);
  CHECK(contains(check.out, "grad_K analytic, grad_T analytic, grad_U analytic, grad_V analytic"));
  CHECK(contains(check.out, " 0 mismatches"));
  CHECK(contains(check.out, "derivative check passed"));
}

TEST_CASE("formula commands: the cache with a stand-in compiler: one compile for two runs at once, damage, fallback") {
  TemporaryFolder folder;
  Environment compiler("NONSEP_CXX", write_fake_compiler(folder).string());
  Environment log("FAKE_LOG", (folder / "calls.log").string());
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  const auto file = write_job(folder / "job.json", job_with({{"formula", paper1d_formula("paper1d")}}));

  SUBCASE("two runs compiling the same model at once compile it once, and both run") {
    Environment slow("FAKE_SLEEP", "1");
    const auto a = start_nonsep({"run", "--quiet", "-o", (folder / "a").string(), file.string()}, folder.path());
    const auto b = start_nonsep({"run", "--quiet", "-o", (folder / "b").string(), file.string()}, folder.path());
    const auto done_a = finish(a), done_b = finish(b);
    INFO(done_a.err << done_b.err);
    CHECK(done_a.status == 0);
    CHECK(done_b.status == 0);
    CHECK(count_lines(folder / "calls.log") == 1);
    CHECK(read_text(folder / "a" / "trajectories.csv") == read_text(folder / "b" / "trajectories.csv"));
  }
  SUBCASE("a damaged or half-written entry is never used: it is compiled again") {
    CHECK(run_nonsep({"run", "--quiet", "-o", (folder / "a").string(), file.string()}, folder.path()).status == 0);
    CHECK(count_lines(folder / "calls.log") == 1);
    CHECK(run_nonsep({"run", "--quiet", "-o", (folder / "b").string(), file.string()}, folder.path()).status == 0);
    CHECK(count_lines(folder / "calls.log") == 1);
    const json summary = read_json(folder / "a" / "summary.json");
    const fs::path entry = folder / "cache" / "formula" / summary["model"]["formula"]["cache_key"].get<std::string>();
    fs::resize_file(entry / "paper1d.so", fs::file_size(entry / "paper1d.so") / 2);
    const auto again = run_nonsep({"run", "--quiet", "-o", (folder / "c").string(), file.string()}, folder.path());
    INFO(again.err);
    CHECK(again.status == 0);
    CHECK(count_lines(folder / "calls.log") == 2);
    fs::remove(entry / "entry.json");
    CHECK(run_nonsep({"run", "--quiet", "-o", (folder / "d").string(), file.string()}, folder.path()).status == 0);
    CHECK(count_lines(folder / "calls.log") == 3);
    CHECK(read_text(folder / "a" / "trajectories.csv") == read_text(folder / "d" / "trajectories.csv"));
  }
  SUBCASE("a cache folder that cannot be created falls back to the temporary folder, saying so") {
    write_text(folder / "not-a-folder", "");
    Environment unwritable("NONSEP_CACHE_DIR", (folder / "not-a-folder" / "cache").string());
    Environment temporary("TMPDIR", folder.path().string());
    const auto result = run_nonsep({"run", "--quiet", "-o", (folder / "a").string(), file.string()}, folder.path());
    INFO(result.err);
    CHECK(result.status == 0);
    CHECK(contains(result.err, "is not writable; using " + folder.path().string()));
    CHECK(count_lines(folder / "calls.log") == 1);
  }
  SUBCASE("a failing compiler is an error with its output, exit 2") {
    Environment fail("FAKE_FAIL", "1");
    const auto result = run_nonsep({"run", "--quiet", file.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(contains(result.err, "fake failure"));
  }
  SUBCASE("nonsep model compile writes NAME.so and refuses another name") {
    const auto model_file = write_job(folder / "model.json", paper1d_formula("paper1d"));
    const auto made =
        run_nonsep({"model", "compile", model_file.string(), "-o", (folder / "paper1d.so").string()}, folder.path());
    INFO(made.err);
    CHECK(made.status == 0);
    CHECK(fs::file_size(folder / "paper1d.so") == fs::file_size(NONSEP_SHIPPED_PLUGIN_DIR "/paper1d.so"));
    const auto named =
        run_nonsep({"model", "compile", model_file.string(), "-o", (folder / "other.so").string()}, folder.path());
    CHECK(named.status == 2);
    CHECK(contains(named.err, "must be named paper1d.so"));
    const auto source = run_nonsep({"model", "compile", model_file.string(), "--print-source"}, folder.path());
    CHECK(contains(source.out, "NONSEP_EXPORT_MODEL(Formula, \"paper1d\""));
    write_text(folder / "bad.json", R"({"T": "p0", "V": "q0 + \"; }"})");
    const auto bad = run_nonsep({"model", "compile", (folder / "bad.json").string()}, folder.path());
    CHECK(bad.status == 2);
    CHECK(contains(bad.err, "bad.json#/V"));
  }
}

}  // namespace test_formula_commands
