// libFuzzer harness over job-file reading: pass 1 (parse_job_text: strict JSON, duplicate keys, nesting) and pass 2
// (parse_job: structure, values, integrator options, time grid, initial states), then pass 3's checks that need no
// plugin (check_model_parameters against a fixed fake metadata, check_dimension). Nothing from the input is ever
// loaded as a plugin or written to disk. Any crash, hang, sanitizer report or uncaught exception is a finding:
// every input, however wrong, must end as a list of JobIssue.
//
// Built with clang by -DNONSEP_FUZZ=ON (tests/fuzz/CMakeLists.txt); the same function is also linked to
// replay_corpus.cpp in every build, so the kept corpus (tests/fuzz/corpus) is a regression test under gcc too.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/json/strict_json.hpp"

namespace {

// A plugin's declared parameters, one of each type, with and without ranges.
const std::vector<nonsep::host::PluginParameter>& fake_parameters() {
  static const std::vector<nonsep::host::PluginParameter> declared = {
      {"epsilon", "number", 0.5, 0.0, 10.0, "", "a number in [0, 10]"},
      {"terms", "integer", 3, 1.0, std::nullopt, "", "an integer >= 1"},
      {"relativistic", "boolean", false, std::nullopt, std::nullopt, "", "a flag"},
      {"mass", "number", 1.0, std::nullopt, std::nullopt, "kg", "any finite number"},
  };
  return declared;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace nonsep::host;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<JobIssue> issues;
  const auto document = parse_job_text(text, issues);
  if (!document) {
    if (issues.empty()) __builtin_trap();  // a refused text must say why
    return 0;
  }
  const Job job = parse_job(*document, "fuzz/job.json", issues);
  if (issues.empty()) {  // what an accepted job promises
    if (job.initial.q.size() != job.initial.count * job.initial.dimension) __builtin_trap();
    if (job.initial.q.size() > max_initial_values) __builtin_trap();
    if (job.plugin.find('\0') != std::string::npos) __builtin_trap();
    if (job.output_directory.string().find('\0') != std::string::npos) __builtin_trap();
    if (!job.is_study()) {
      const auto bound = job.run().analysis.max_relative_energy_error;
      if (bound && !(*bound > 0.0 && std::isfinite(*bound))) __builtin_trap();
    } else if (job.initial.count != 1) {
      __builtin_trap();  // a study has one initial state
    }
  }
  check_model_parameters(job.parameters, fake_parameters(), issues);
  check_swept_parameters(job, fake_parameters(), issues);
  for (std::size_t dimension : {std::size_t{1}, std::size_t{2}}) check_dimension(job.initial, dimension, issues);
  for (const auto& issue : issues) (void)to_string(issue);
  if (!issues.empty()) (void)InvalidJob("fuzz/job.json", issues).what();
  return 0;
}
