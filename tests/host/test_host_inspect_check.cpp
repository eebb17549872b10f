// `nonsep inspect --check` on real models: sample points from a box or a job's initial states, parameters from the
// command line or a job, the tolerance; NaN outside a model's domain agrees with NaN; numbers in scientific
// notation; a check that compares nothing or does not fit in memory is invalid input (exit 2), never a pass.
// The test plugin domain_edge (tests/host/plugins/domain_edge.cpp) has V = sum log(q_i - edge), NaN for q_i <= edge.
#include <doctest/doctest.h>

#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "address_sanitizer.hpp"
#include "host_test_support.hpp"

namespace test_host_inspect_check {

using nlohmann::json;
using namespace nonsep::host_testing;

// AddressSanitizer reserves terabytes of shadow memory: it cannot run under an address-space limit
// (NONSEP_TEST_ADDRESS_SANITIZER, address_sanitizer.hpp).

namespace {

// The points printed with the mismatches, "<function>[i] at p = (x, y): ..." -> {"p", {x, y}}.
std::vector<std::pair<std::string, std::vector<double>>> mismatch_points(const std::string& text) {
  static const std::regex line(R"re(\] at ([pq]) = \(([^)]*)\))re");
  std::vector<std::pair<std::string, std::vector<double>>> points;
  for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) {
    std::vector<double> x;
    std::string numbers = (*it)[2];
    for (std::size_t at = 0; at < numbers.size();) {
      std::size_t used = 0;
      x.push_back(std::stod(numbers.substr(at), &used));
      at += used;
      while (at < numbers.size() && (numbers[at] == ',' || numbers[at] == ' ')) ++at;
    }
    points.emplace_back((*it)[1], x);
  }
  return points;
}

// A single run of domain_edge with edge = 1 from (q, p) = ((2, 3), (0.5, -0.25)).
json domain_job() {
  return {{"model", {{"plugin", "domain_edge"}, {"parameters", {{"edge", 1.0}, {"dimension", 2}}}}},
          {"integrator", {{"scheme", "basic"}, {"t2", -2.0}}},
          {"initial", {{"q", {2.0, 3.0}}, {"p", {0.5, -0.25}}}},
          {"time", {{"dt", 0.01}, {"steps", 10}}}};
}

}  // namespace

TEST_CASE("inspect --check: NaN outside the model's domain agrees with NaN, in the differences and in batches") {
  TemporaryFolder folder;
  const auto result = run_nonsep({"inspect", "domain_edge", "--check"}, folder.path());
  INFO(result.out, result.err);
  // The default box [-1.5, 1.5] holds points with q < 0, where every V function is NaN.
  CHECK(result.out.find(" entries were NaN both computed and differenced (points outside the model's domain)") !=
        std::string::npos);
  CHECK(result.out.find("batch consistency: one call on all points equals one call per point") != std::string::npos);
  CHECK(result.out.find("threads: two instances on two threads give the numbers of one thread") != std::string::npos);
  CHECK(result.out.find("alone but nan in a batch") == std::string::npos);
  // Errors, points and values in scientific notation.
  CHECK(std::regex_search(result.out, std::regex(R"(largest relative error \d\.\d{3}e[-+]\d\d\n)")));
}

TEST_CASE("inspect --check --box LO,HI samples there, --tolerance is the allowed error") {
  TemporaryFolder folder;
  auto result = run_nonsep({"inspect", "domain_edge", "--check", "--box", "0.5,2"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("sample points: 16 random in [5.000e-01, 2.000e+00]^1; tolerance 1.000e-06") !=
        std::string::npos);
  CHECK(result.out.find("NaN both") == std::string::npos);
  CHECK(result.out.find("derivative check passed") != std::string::npos);

  // A tolerance below rounding: every inexact entry is a mismatch, printed with its point, all inside the box.
  result = run_nonsep({"inspect", "blowup", "--check", "--box", "3,4", "--tolerance", "1e-300"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("derivative check FAILED") != std::string::npos);
  const auto points = mismatch_points(result.out);
  REQUIRE(!points.empty());
  for (const auto& [variable, x] : points)
    for (double xi : x) CHECK((xi >= 3.0 && xi <= 4.0));
  CHECK(std::regex_search(result.out, std::regex(R"(computed -?\d\.\d{6}e[-+]\d\d, finite difference )")));

  for (const char* bad : {"2,1", "1", "a,b", "0,inf"}) {
    CAPTURE(bad);
    result = run_nonsep({"inspect", "blowup", "--check", "--box", bad}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("--box expects LO,HI with finite numbers LO < HI") != std::string::npos);
  }
  CHECK(run_nonsep({"inspect", "blowup", "--check", "--tolerance", "-1"}, folder.path()).status == 2);
  CHECK(run_nonsep({"inspect", "blowup", "--box", "0,1"}, folder.path()).status == 2);  // needs --check
}

TEST_CASE("inspect --check --job and --points-from take a job's parameters and initial states") {
  TemporaryFolder folder;
  const auto job = write_job(folder / "domain.json", domain_job());
  auto result = run_nonsep({"inspect", "domain_edge", "--check", "--job", job.string(), "--points-from", job.string()},
                           folder.path());
  INFO(result.out, result.err);
  CHECK(result.status == 0);
  CHECK(result.out.find("(the parameters of " + job.string() + ", dimension 2)") != std::string::npos);
  CHECK(result.out.find("sample points: 1 given (p for T, q for V); tolerance") != std::string::npos);
  // One state of dimension 2: the gradient (2) and Hessian (4) of T at p, the same of V at q.
  CHECK(result.out.find("12 derivative entries compared") != std::string::npos);

  result = run_nonsep({"inspect", "domain_edge", "--check", "--job", job.string(), "--points-from", job.string(),
                       "--tolerance", "1e-300"},
                      folder.path());
  const auto points = mismatch_points(result.out);
  REQUIRE(!points.empty());
  for (const auto& [variable, x] : points)
    CHECK(x == (variable == "p" ? std::vector<double>{0.5, -0.25} : std::vector<double>{2.0, 3.0}));

  // --parameter overrides the job's: with edge = 2.5 the state q = (2, 3) is outside the domain in q_0.
  result = run_nonsep({"inspect", "domain_edge", "--check", "--job", job.string(), "--parameter", "edge=2.5",
                       "--points-from", job.string()},
                      folder.path());
  CHECK(result.out.find("(the parameters of " + job.string() + ", --parameter, dimension 2)") != std::string::npos);
  CHECK(result.out.find("entries were NaN both") != std::string::npos);

  json other = domain_job();
  other["model"] = {{"plugin", "blowup"}, {"parameters", {{"dimension", 2}}}};
  const auto other_file = write_job(folder / "other.json", other);
  result = run_nonsep({"inspect", "domain_edge", "--check", "--points-from", other_file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("--points-from " + other_file.string() + ": the job uses the plugin 'blowup'") !=
        std::string::npos);
}

TEST_CASE("inspect --check --parameter name=value: parameters of the check, each refused clearly when wrong") {
  TemporaryFolder folder;
  auto result =
      run_nonsep({"inspect", "domain_edge", "--check", "--parameter", "dimension=3", "--box", "0.5,2"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("(--parameter, dimension 3)") != std::string::npos);
  CHECK(result.out.find("]^3;") != std::string::npos);
  result = run_nonsep({"inspect", "domain_edge", "--check", "--parameter", "edge"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("--parameter expects name=value") != std::string::npos);
  result = run_nonsep({"inspect", "domain_edge", "--check", "--parameter", "colour=1"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("unknown parameter 'colour'") != std::string::npos);
}

TEST_CASE("inspect --check that compares nothing is invalid input (dimension 0), and never a pass") {
  TemporaryFolder folder;
  auto result = run_nonsep({"inspect", "domain_edge", "--check", "--parameter", "dimension=0"}, folder.path());
  CHECK(result.status == 2);
  // The loader refuses an instance of dimension 0 (the ABI requires n > 0) before anything could be compared.
  CHECK(result.err.find("the instance has dimension 0") != std::string::npos);
  CHECK(result.out.find("passed") == std::string::npos);
  // Only gradients: nothing to difference them against; the consistency checks still run, but it is no pass.
  result = run_nonsep({"inspect", "blowup_gradients_only", "--check"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("no derivative was compared with finite differences") != std::string::npos);
  CHECK(result.out.find("derivative check passed") == std::string::npos);
}

TEST_CASE("inspect --check too large for memory is invalid input with a clear message") {
  TemporaryFolder folder;
  auto result = run_nonsep({"inspect", "domain_edge", "--check", "--parameter", "dimension=1000000000"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("dimension 1000000000") != std::string::npos);
  CHECK(result.err.find("of memory, more than this machine's") != std::string::npos);
#if defined(NONSEP_TEST_ADDRESS_SANITIZER)
  MESSAGE("skipped under AddressSanitizer: its shadow memory does not run under an address-space limit");
#else
  // Fits the machine, not an address space of 256 MB: std::bad_alloc during the check.
  use_test_plugins();
  const std::string command = "ulimit -v 262144 && exec " + std::string(NONSEP_EXECUTABLE) +
                              " inspect domain_edge --check --parameter dimension=2000 > " +
                              (folder / "out.txt").string() + " 2> " + (folder / "err.txt").string();
  const int status = std::system(command.c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 2);
  const std::string err = read_text(folder / "err.txt");
  INFO(err);
  CHECK(err.find("nonsep: the derivative check of domain_edge (dimension 2000") == 0);
  CHECK((err.find("ran out of memory") != std::string::npos ||
         err.find("more than this machine's") != std::string::npos));
  CHECK(err.find("unexpected error") == std::string::npos);
#endif
}

TEST_CASE(
    "a wrong gradient: run and validate refuse it at /model/plugin, and inspect --check names it as the culprit") {
  TemporaryFolder folder;
  // blowup_wrong_gradient: grad V = 2 q^3 where V = q^4 / 4; its Hessian 3 q^2 is right.
  json job = {{"model", {{"plugin", "blowup_wrong_gradient"}}},
              {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
              {"initial", json::array({{{"q", {1.0}}, {"p", {0.5}}}, {{"q", {0.5}}, {"p", {0.25}}}})},
              {"time", {{"dt", 0.001}, {"steps", 10}}}};
  const auto file = write_job(folder / "wrong.json", job);
  for (const char* command : {"run", "validate"}) {
    CAPTURE(command);
    const auto result = run_nonsep({command, file.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("/model/plugin: found the plugin 'blowup_wrong_gradient', whose grad_V[0] at initial state 0 "
                          "(q = (1.000000e+00)) is 2.000000e+00 where the finite difference of value_V gives "
                          "1.000000e+00") != std::string::npos);
    CHECK(result.err.find("--check --points-from " + file.string() + "` lists every mismatch") != std::string::npos);
  }
  CHECK_FALSE(std::filesystem::exists(folder / "wrong.out" / "summary.json"));  // nothing was run
  job["model"]["plugin"] = "blowup";                                            // the right gradient: the same job runs
  write_job(file, job);
  CHECK(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);

  auto result = run_nonsep({"inspect", "blowup_wrong_gradient", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("  hessian_V[0] at q = (") != std::string::npos);  // differenced from the wrong gradient
  CHECK(result.out.find("likely culprit: grad_V, which disagrees with the differences of value_V; hessian_V agrees "
                        "with the second differences of value_V") != std::string::npos);
  result = run_nonsep({"inspect", "blowup_wrong_hessian", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("likely culprit") == std::string::npos);  // its gradient is right: the Hessian is wrong
}

}  // namespace test_host_inspect_check
