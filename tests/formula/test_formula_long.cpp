// Formulas at the length limit through the `nonsep` executable with the real compiler: a product of about 400
// distinct factors and a long sum, both cut into parts (cpp_source.hpp), compile within a bound on the compiler's
// CPU time, and give the states of the shipped paper1d plugin: the product's factors cancel in pairs, (q0 + k)/(q0 +
// k) with k > 10 (the states stay within |q0| < 2), and the sum's terms in pairs, (p0 + k)^2 - (p0 + k)^2, so a part
// that lost a sign would show.
#include <doctest/doctest.h>
#include <sys/resource.h>

#include <string>

#include "formula_test_support.hpp"
#include "nonsep/host/formula/expression.hpp"

namespace test_formula_long {

using nlohmann::json;
using namespace nonsep::host_testing;
using namespace nonsep::formula_testing;
using nonsep::host::formula::max_formula_length;

namespace {

// CPU seconds of the children waited for so far (nonsep and, through it, the compiler).
double children_cpu_seconds() {
  rusage usage{};
  ::getrusage(RUSAGE_CHILDREN, &usage);
  const auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

}  // namespace

TEST_CASE("formula commands: formulas at the length limit compile in bounded time and give the short ones' states") {
  TemporaryFolder folder;
  Environment cache("NONSEP_CACHE_DIR", (folder / "cache").string());
  std::string V = "(q0^2/2 + q0^4/12)";
  for (int k = 1;; ++k) {
    const std::string pair = "*(q0 + " + std::to_string(k + 10) + ")/(q0 + " + std::to_string(k + 10) + ")";
    if (V.size() + pair.size() > max_formula_length) break;
    V += pair;
  }
  std::string T = "p0 + p0^3/6";
  for (int k = 1; k <= 60; ++k) T += " + (p0 + " + std::to_string(k) + ")^2 - (p0 + " + std::to_string(k) + ")^2";
  const json model = {{"name", "long_paper1d"}, {"T", T}, {"V", V}};
  const auto formula_file = write_job(folder / "formula.json", job_with({{"formula", model}}));
  // Before formulas were cut into parts, a product of 467 distinct factors ran into any reasonable compile time limit.
  Environment limit("NONSEP_COMPILE_TIME_LIMIT", "900");
  const double cpu_before = children_cpu_seconds();
  const auto run = finish(
      start_nonsep({"run", "--quiet", "-o", (folder / "formula").string(), formula_file.string()}, folder.path()),
      std::chrono::seconds(1000));
  const double cpu = children_cpu_seconds() - cpu_before;
  INFO("stderr: " << run.err);
  MESSAGE("the compile and run of a " << V.size() << "-character product and a " << T.size() << "-character sum took "
                                      << cpu << " s of CPU time");
  REQUIRE(run.status == 0);
  CHECK(cpu < 300);

  check_final_states_match_paper1d(folder, folder / "formula", 1e-12);
}

}  // namespace test_formula_long
