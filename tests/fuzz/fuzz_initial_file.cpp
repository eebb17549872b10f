// libFuzzer harness over reading initial states from a file (/initial/file, job/initial_file.cpp): arbitrary bytes
// as a .npy file and as a .csv file of a fixed job, read by parse_job. Every input is tried as both. Any crash, hang,
// sanitizer report or exception is a finding, and so is an accepted file that breaks what the reader promises: at
// least one state, within max_initial_states and max_initial_values, every number finite; a refused one is one
// issue at /initial/file. The fuzzer's -rss_limit_mb catches a reader whose memory grows with the file.
//
// Nothing from the input is loaded or written anywhere but one scratch folder (two files). Replayed over
// tests/fuzz/initial_file_corpus in every build (host.fuzz_initial_file_replay).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nonsep/host/job.hpp"

namespace {

const std::filesystem::path& scratch() {
  static const std::filesystem::path folder = [] {
    const auto made = std::filesystem::temp_directory_path() / ("nonsep-fuzz-initial-" + std::to_string(::getpid()));
    std::filesystem::create_directories(made);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch(), ignored);
    });
    return made;
  }();
  return folder;
}

void read_as(const std::string& name, const std::uint8_t* data, std::size_t size) {
  using namespace nonsep::host;
  {
    std::ofstream out(scratch() / name, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  const nlohmann::json document = {{"model", {{"plugin", "fuzz"}}},
                                   {"integrator", {{"scheme", "basic"}}},
                                   {"initial", {{"file", name}}},
                                   {"time", {{"dt", 0.1}, {"steps", 1}}},
                                   {"output", {{"every", 0}}}};
  std::vector<JobIssue> issues;
  const Job job = parse_job(document, scratch() / "job.json", issues);
  if (!issues.empty()) {
    if (issues.size() != 1 || issues[0].path != "/initial/file" || issues[0].found.empty()) __builtin_trap();
    (void)to_string(issues[0]);
    return;
  }
  const InitialStates& states = job.initial;
  if (states.count == 0 || states.dimension == 0 || states.count > max_initial_states) __builtin_trap();
  if (states.q.size() != states.count * states.dimension || states.p.size() != states.q.size()) __builtin_trap();
  if (states.q.size() > max_initial_values) __builtin_trap();
  for (std::size_t i = 0; i < states.q.size(); ++i)
    if (!std::isfinite(states.q[i]) || !std::isfinite(states.p[i])) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  read_as("states.npy", data, size);
  read_as("states.csv", data, size);
  return 0;
}
