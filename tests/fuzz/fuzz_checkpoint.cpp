// libFuzzer harness over reading checkpoints (`nonsep run --resume`): arbitrary bytes as checkpoint.json of a fixed
// job (paper1d, three trajectories, analysis on), read by load_checkpoint and, when accepted, restored into the
// observers that keep state (energy error, closest return, runaway). Every input is tried twice: as it is (the format
// and the checksum must refuse what was damaged) and, when it is a JSON object, signed anew with this job's fingerprint
// and a correct checksum, so that the fuzzer reaches the content checks behind them (what an edited checkpoint
// with a recomputed checksum would meet). Any crash, hang, sanitizer report or exception other than
// CheckpointError is a finding, and so is an accepted checkpoint that breaks what load_checkpoint promises.
//
// The plugin is the build's paper1d (NONSEP_FUZZ_PLUGIN); nothing from the input is loaded or written anywhere
// but one scratch file. Replayed over tests/fuzz/checkpoint_corpus in every build (host.fuzz_checkpoint_replay).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/observers/closest_return.hpp"
#include "nonsep/host/observers/energy_error.hpp"
#include "nonsep/host/observers/runaway.hpp"
#include "nonsep/host/output/content_hash.hpp"

namespace {

using nonsep::host::TrajectoryStatus;

struct Fixture {
  std::filesystem::path folder;
  std::optional<nonsep::host::LoadedJob> loaded;
  std::string fingerprint;
};

Fixture& fixture() {
  static Fixture fixture = [] {
    Fixture made;
    made.folder = std::filesystem::temp_directory_path() / ("nonsep-fuzz-checkpoint-" + std::to_string(::getpid()));
    std::filesystem::create_directories(made.folder);
    static std::filesystem::path scratch;
    scratch = made.folder;
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch, ignored);
    });
    const nlohmann::json job = {
        {"model", {{"plugin", NONSEP_FUZZ_PLUGIN}}},
        {"integrator", {{"scheme", "triplet"}, {"order", "4/3"}}},
        {"initial", {{{"q", {0.5}}, {"p", {0.0}}}, {{"q", {1.0}}, {"p", {0.1}}}, {{"q", {1.5}}, {"p", {-0.2}}}}},
        {"time", {{"dt", 0.01}, {"steps", 1000}}},
        {"output", {{"every", 10}}},
        {"analysis", {{"closest_return_after", 0.5}, {"max_relative_energy_error", 0.5}}}};
    std::ofstream(made.folder / "job.json") << job.dump();
    made.loaded.emplace(nonsep::host::load_job(made.folder / "job.json"));
    made.fingerprint = nonsep::host::job_fingerprint(*made.loaded);
    return made;
  }();
  return fixture;
}

// What an accepted checkpoint promises (checkpoint_file.hpp): a step of the job, the active trajectories in increasing
// order with finite states of the job's dimension, a record for every trajectory, "running" exactly for the active.
void check_accepted(const nonsep::host::Checkpoint& checkpoint, const nonsep::host::Job& job) {
  const auto& state = checkpoint.driver;
  const std::size_t n = job.initial.dimension;
  if (state.step > job.run().time.steps) __builtin_trap();
  if (state.records.size() != job.initial.count) __builtin_trap();
  if (state.q.size() != state.active.size() * n || state.p.size() != state.q.size()) __builtin_trap();
  for (std::size_t i = 0; i < state.active.size(); ++i) {
    if (state.active[i] >= job.initial.count || (i > 0 && state.active[i] <= state.active[i - 1])) __builtin_trap();
    if (state.records[state.active[i]].status != TrajectoryStatus::running) __builtin_trap();
  }
  for (std::size_t i = 0; i < state.q.size(); ++i)
    if (!std::isfinite(state.q[i]) || !std::isfinite(state.p[i])) __builtin_trap();
  std::size_t running = 0;
  for (const auto& record : state.records) running += record.status == TrajectoryStatus::running;
  if (running != state.active.size()) __builtin_trap();
  if (!checkpoint.observers.is_object()) __builtin_trap();
}

void try_checkpoint(const std::string& text) {
  Fixture& f = fixture();
  const auto path = f.folder / "checkpoint.json";
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
  const nonsep::host::Job& job = f.loaded->job;
  try {
    const auto checkpoint = nonsep::host::load_checkpoint(path, *f.loaded);
    check_accepted(checkpoint, job);
    nonsep::host::EnergyErrorObserver energy(job.initial.count, 0, job.run().analysis.max_relative_energy_error);
    nonsep::host::ClosestReturnObserver closest(*job.run().analysis.closest_return_after, job.initial.dimension,
                                                job.initial.q, job.initial.p);
    nonsep::host::RunawayObserver runaway(job.initial.q, job.initial.p, job.initial.count, job.initial.dimension,
                                          job.run().time);
    for (nonsep::host::CheckpointedObserver* observer : {static_cast<nonsep::host::CheckpointedObserver*>(&energy),
                                                         static_cast<nonsep::host::CheckpointedObserver*>(&closest),
                                                         static_cast<nonsep::host::CheckpointedObserver*>(&runaway)})
      if (checkpoint.observers.contains(observer->name())) observer->restore(checkpoint.observers[observer->name()]);
  } catch (const nonsep::host::CheckpointError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try_checkpoint(text);
  nlohmann::json document = nlohmann::json::parse(text, nullptr, false);
  if (document.is_object()) {
    document.erase("checksum");
    document["job_fingerprint"] = fixture().fingerprint;
    document["checksum"] = nonsep::host::content_hash_hex(nonsep::host::content_hash(document.dump()));
    try_checkpoint(document.dump());
  }
  return 0;
}
