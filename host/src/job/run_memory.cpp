// What a single run keeps in memory, estimated from the job before anything runs, and the memory this process can
// still take (job.hpp: estimate_run_memory, available_memory, memory_issue).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "nonsep/host/job.hpp"

namespace nonsep::host {

namespace {

// "17.3 GiB", "512.0 MiB".
std::string bytes_text(double bytes) {
  const bool gib = bytes >= 1024.0 * 1024.0 * 1024.0;
  char text[48];
  std::snprintf(text, sizeof text, "%.1f %s", bytes / (gib ? 1073741824.0 : 1048576.0), gib ? "GiB" : "MiB");
  return text;
}

// The number after `key` in a "Key: value" file such as /proc/meminfo or /proc/self/status (in kB there), or -1.
double field(const std::string& file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key + ":", 0) == 0) {
      double value = -1.0;
      std::istringstream(line.substr(key.size() + 1)) >> value;
      return value;
    }
  return -1.0;
}

// The first number of a file such as /sys/fs/cgroup/memory.max; -1 when missing or "max".
double number_in(const std::string& file) {
  std::ifstream in(file);
  double value = -1.0;
  return in >> value ? value : -1.0;
}

// The cgroup (v2) of this process, as /sys/fs/cgroup sees it ("" for the root), or nothing.
std::optional<std::string> cgroup_folder() {
  std::ifstream in("/proc/self/cgroup");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("0::", 0) == 0) return "/sys/fs/cgroup" + line.substr(3);
  return std::nullopt;
}

}  // namespace

double MemoryEstimate::total() const {
  double sum = 0.0;
  for (const Part& part : parts) sum += part.bytes;
  return sum;
}

MemoryEstimate estimate_run_memory(const LoadedJob& loaded, std::size_t trajectories) {
  const Job& job = loaded.job;
  const auto n = static_cast<double>(job.initial.dimension), all = static_cast<double>(job.initial.count);
  const auto stepped = static_cast<double>(std::min(trajectories, job.initial.count));
  constexpr double number = sizeof(double);
  const double state = 2 * n * number;
  MemoryEstimate estimate;
  const auto add = [&](std::string key, std::string what, double bytes) {
    if (bytes > 0) estimate.parts.push_back({std::move(key), std::move(what), bytes});
  };
  add("/initial", "the states (the job's, and per trajectory stepped the run's, their copy and the final state)",
      all * state + 3 * stepped * state);
  if (!job.is_study()) {
    const SingleRun& run = job.run();
    const Analysis& analysis = run.analysis;
    const auto k = static_cast<double>(analysis.tangent_vectors());
    add(analysis.tangent_key(),
        "the tangent vectors (" + std::to_string(analysis.tangent_vectors()) + " per trajectory, and their copy)",
        2 * stepped * (2 * n * k + k * k) * number);
    if (analysis.error_estimate) {
      const double points = run.every > 0 ? static_cast<double>(run.time.steps / run.every + 1) : 101.0;
      add("/analysis/error_estimate",
          "the half-step run's states at " + std::to_string(static_cast<std::uint64_t>(points)) + " comparison steps",
          stepped * (points * (2 * n + 2) + 2 * 2 * n) * number);
    }
    if (analysis.poincare) add("/analysis/poincare", "the state before each step", stepped * state);
    for (const auto& indicator : analysis.sampled_indicators()) {
      // Per trajectory and signal the samples not yet written, and per block (at most 8 + stepped / 2) one
      // trajectory's m signals and an analysis's FFT, window and transforms' tables: some m + 5 copies of N complex
      // numbers.
      const SampleNeeds needs = indicator->needs().samples;
      const double samples = static_cast<double>(run.time.steps / needs.every);
      const double blocks = std::min(stepped, 8.0 + stepped / 2.0);
      add("/analysis/" + indicator->name(), "the samples not yet in " + needs.file + " and the blocks' analyses",
          stepped * static_cast<double>(std::max<std::size_t>(needs.degrees.size(), 1)) *
                  static_cast<double>(samples_in_memory) * 2 * number +
              blocks * (static_cast<double>(needs.degrees.size()) + 5) * samples * 2 * number);
    }
    if (analysis.closest_return_after)
      add("/analysis/closest_return_after", "the initial states compared with", stepped * state);
    if (run.every > 0)
      add("/output/every",
          run.format == OutputFormat::hdf5 ? "a sample of every trajectory and its chunk buffer (results.h5)"
                                           : "a sample of every trajectory as text (trajectory.csv)",
          run.format == OutputFormat::hdf5 ? 2 * stepped * (2 * n + 1) * number : stepped * (2 * n + 3) * 25.0);
    add("/checkpoint", "checkpoint.json while it is written",
        stepped * (2 * n + 2 * n * k + k) * checkpoint_bytes_per_number);
  }
  std::stable_sort(estimate.parts.begin(), estimate.parts.end(),
                   [](const auto& a, const auto& b) { return a.bytes > b.bytes; });
  return estimate;
}

std::optional<AvailableMemory> available_memory() {
  std::optional<AvailableMemory> least;
  const auto offer = [&](double bytes, std::string source) {
    if (bytes >= 0 && (!least || bytes < least->bytes)) least = AvailableMemory{bytes, std::move(source)};
  };
  if (const double kb = field("/proc/meminfo", "MemAvailable"); kb >= 0) {
    offer(kb * 1024.0, "MemAvailable in /proc/meminfo");
  } else if (const long pages = ::sysconf(_SC_AVPHYS_PAGES), size = ::sysconf(_SC_PAGESIZE); pages > 0 && size > 0) {
    offer(static_cast<double>(pages) * static_cast<double>(size), "the free pages (sysconf)");
  }
  if (const auto folder = cgroup_folder())
    if (const double limit = number_in(*folder + "/memory.max"), used = number_in(*folder + "/memory.current");
        limit >= 0 && used >= 0)
      offer(std::max(0.0, limit - used), "the cgroup's memory.max less memory.current");
  if (rlimit limit{}; ::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    if (const double kb = field("/proc/self/status", "VmSize"); kb >= 0)
      offer(std::max(0.0, static_cast<double>(limit.rlim_cur) - kb * 1024.0),
            "RLIMIT_AS (ulimit -v) less the address space in use");
  return least;
}

std::optional<JobIssue> memory_issue(const LoadedJob& loaded, std::size_t trajectories) {
  const MemoryEstimate estimate = estimate_run_memory(loaded, trajectories);
  const auto available = available_memory();
  if (!available || estimate.total() <= available->bytes) return std::nullopt;
  std::string parts;
  for (std::size_t i = 0; i < estimate.parts.size() && i < 3; ++i)
    parts += (i == 0 ? "" : ", ") + estimate.parts[i].what + " " + bytes_text(estimate.parts[i].bytes) + " (" +
             estimate.parts[i].key + ")";
  const std::string share = trajectories < loaded.job.initial.count
                                ? " (" + std::to_string(trajectories) + " of its " +
                                      std::to_string(loaded.job.initial.count) + " trajectories in this process)"
                                : "";
  return JobIssue{estimate.parts.front().key,
                  "a run that needs about " + bytes_text(estimate.total()) + " of memory" + share + ": " + parts,
                  "a run that fits in the " + bytes_text(available->bytes) + " available (" + available->source +
                      "): fewer trajectories, tangent vectors or samples kept, or more processes (mpirun)"};
}

}  // namespace nonsep::host
