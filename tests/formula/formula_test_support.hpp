#pragma once
// Helpers for the formula tests that run `nonsep`: environment variables set for a scope, a formula twin of
// paper1d, a job around a model, its run compared with the shipped paper1d's, and a stand-in compiler that copies the
// shipped paper1d.so instead of compiling.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include "host_test_support.hpp"

namespace nonsep::formula_testing {

namespace fs = std::filesystem;
using host_testing::read_text;
using host_testing::TemporaryFolder;
using host_testing::write_text;
using nlohmann::json;

// Sets an environment variable for its lifetime, then restores the previous value.
class Environment {
 public:
  Environment(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~Environment() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }
  Environment(const Environment&) = delete;
  Environment& operator=(const Environment&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

inline json paper1d_formula(const std::string& name) {
  return {{"name", name}, {"T", "p0 + p0^3/6"}, {"V", "q0^2/2 + q0^4/12"}};
}

// paper1d's H = T'(p)^2 V''(q) written as one formula of q0 and p0, a model given by H.
inline json paper1d_hamiltonian_formula(const std::string& name) {
  return {{"name", name}, {"H", "(1 + p0^2/2)^2 * (1 + q0^2)"}};
}

inline const json triplet_integrator = {{"scheme", "triplet"}, {"order", "4/3"}, {"t2", -2.0}};

inline json job_with(json model, const json& integrator = triplet_integrator) {
  return {{"model", std::move(model)},
          {"integrator", integrator},
          {"initial", {{{"q", {0.5}}, {"p", {0.25}}}, {{"q", {-1.0}}, {"p", {0.75}}}}},
          {"time", {{"dt", 0.01}, {"steps", 300}}},
          {"output", {{"every", 0}}}};
}

// Runs job_with the shipped paper1d plugin (and `integrator`) into folder/plugin and checks that the formula model's
// run of the same job, in `formula_run`, ends at its final states to `tolerance` relative to |(q, p)| (a component
// passing near 0 has no relative accuracy of its own). Returns the formula run (read_run).
inline json check_final_states_match_paper1d(const TemporaryFolder& folder, const fs::path& formula_run,
                                             double tolerance, const json& integrator = triplet_integrator) {
  const auto plugin_file =
      host_testing::write_job(folder / "plugin.json", job_with({{"plugin", "paper1d"}}, integrator));
  REQUIRE(host_testing::run_nonsep({"run", "--quiet", "-o", (folder / "plugin").string(), plugin_file.string()},
                                   folder.path())
              .status == 0);
  const json by_formula = host_testing::read_run(formula_run);
  const json by_plugin = host_testing::read_run(folder / "plugin");
  REQUIRE(by_formula["trajectories"].size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    const json& a = by_formula["trajectories"][i]["final"];
    const json& b = by_plugin["trajectories"][i]["final"];
    const double scale = std::hypot(b["q"][0].get<double>(), b["p"][0].get<double>());
    for (const char* part : {"q", "p"})
      CHECK(std::abs(a[part][0].get<double>() - b[part][0].get<double>()) <= tolerance * scale);
  }
  return by_formula;
}

// A stand-in compiler, steered by variables:
//   --version: prints one line (FAKE_VERSION_LINES more lines of 100 characters; FAKE_VERSION_SLEEP seconds first);
//   otherwise: appends a line to FAKE_LOG; FAKE_FAIL: fails with a compiler-like message; FAKE_PIDS: starts
//   `sleep FAKE_SLEEP` in the background, appends its and its own process id to that file and waits for it (else
//   sleeps FAKE_SLEEP seconds itself); FAKE_LINGER: leaves `sleep FAKE_LINGER` running in the background with the
//   output pipe and appends its id to FAKE_PIDS; then copies the shipped paper1d.so to the -o argument (the soft
//   file size limit lifted first: a test may limit nonsep's files, not the plugin).
inline fs::path write_fake_compiler(const TemporaryFolder& folder) {
  const fs::path script = folder / "fake-c++";
  write_text(
      script,
      "#!/bin/sh\n"
      "if [ \"$1\" = --version ]; then\n"
      "  sleep \"${FAKE_VERSION_SLEEP:-0}\"; echo 'fake compiler 1'\n"
      "  i=0; while [ \"$i\" -lt \"${FAKE_VERSION_LINES:-0}\" ]; do\n"
      "    echo 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx';"
      " i=$((i+1)); done\n"
      "  exit 0\n"
      "fi\n"
      "echo call >> \"$FAKE_LOG\"\n"
      "if [ -n \"$FAKE_FAIL\" ]; then echo 'model.cpp:1:1: error: fake failure' >&2; exit 1; fi\n"
      "if [ -n \"$FAKE_PIDS\" ] && [ -n \"$FAKE_SLEEP\" ]; then\n"
      "  sleep \"$FAKE_SLEEP\" & echo \"$! $$\" >> \"$FAKE_PIDS\"; wait\n"
      "else sleep \"${FAKE_SLEEP:-0}\"; fi\n"
      "if [ -n \"$FAKE_LINGER\" ]; then sleep \"$FAKE_LINGER\" & echo \"$!\" >> \"$FAKE_PIDS\"; fi\n"
      "ulimit -S -f unlimited\n"
      "out=''; previous=''\n"
      "for a in \"$@\"; do [ \"$previous\" = -o ] && out=\"$a\"; previous=\"$a\"; done\n"
      "cp '" NONSEP_SHIPPED_PLUGIN_DIR "/paper1d.so' \"$out\"\n");
  fs::permissions(script, fs::perms::owner_all);
  return script;
}

inline std::size_t count_lines(const fs::path& file) {
  if (!fs::exists(file)) return 0;
  const std::string text = read_text(file);
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace nonsep::formula_testing
