// The cost of writing samples as CSV (trajectory.csv) and as HDF5 (results.h5, output.format "hdf5"), for
// docs/performance.md ("HDF5 against CSV output"): one ensemble of paper2d (a 316 x 316 grid of (q0, p0), 99856
// trajectories of dimension 2, the basic step, 300 steps of dt = 0.001) run through nonsep::host::run_job in four
// configurations, interleaved, each repeated:
//   none        output.every = 0: no samples (summary.json and trajectories.csv only)
//   hdf5 none   output.every = 0, format hdf5: results.h5 with the tables and no /samples
//   csv         output.every = 20 (16 samples: steps 0, 20, ..., 300): trajectory.csv
//   hdf5        output.every = 20, format hdf5: results.h5
// Printed: wall seconds (median, min, max over the repetitions) and the sizes of trajectory.csv and results.h5.
// Checked: every run completes, and trajectories.csv is the same bytes in both formats (exit status 1 if not).
//
// Usage: nonsep_bench_output_formats [--smoke] [--repetitions N] [--threads N]
//   --smoke        1024 trajectories, 2 repetitions (the ctest bench.output_formats.smoke)
//   --repetitions  per configuration (default 5)
//   --threads      worker threads of every run (default 2)
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"

namespace {

using json = nlohmann::json;

struct Configuration {
  std::string name;
  std::uint64_t every;
  std::string format;
  std::vector<double> seconds;
  std::uintmax_t bytes = 0;  // of the samples' file, or of results.h5
};

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

nonsep::host::LoadedJob make_job(const std::filesystem::path& folder, const Configuration& c, std::size_t side) {
  const json axis = {{"from", -1.0}, {"to", 1.0}, {"count", side}};
  const json job = {{"model", {{"plugin", "paper2d"}, {"parameters", {{"coupling", 0.2}}}}},
                    {"integrator", {{"scheme", "basic"}}},
                    {"initial", {{"grid", {{"q", {axis, 0.0}}, {"p", {axis, 0.5}}}}}},
                    {"time", {{"dt", 0.001}, {"steps", 300}}},
                    {"output", {{"every", c.every}, {"format", c.format}}}};
  std::string name = c.name;
  std::replace(name.begin(), name.end(), ' ', '_');
  const auto file = folder / (name + ".json");
  std::ofstream(file) << job.dump();
  return nonsep::host::load_job(file);
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int repetitions = 5;
  unsigned threads = 2;
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument == "--smoke")
      smoke = true;
    else if (argument == "--repetitions" && i + 1 < argc)
      repetitions = std::atoi(argv[++i]);
    else if (argument == "--threads" && i + 1 < argc)
      threads = static_cast<unsigned>(std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: %s [--smoke] [--repetitions N] [--threads N]\n", argv[0]);
      return 2;
    }
  }
  if (smoke) repetitions = 2;
  const std::size_t side = smoke ? 32 : 316;
  const auto folder = std::filesystem::temp_directory_path() / ("nonsep-bench-output-" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder);
  // Pairs: CSV, then HDF5 with the same `every`.
  std::vector<Configuration> configurations{
      {"none", 0, "csv", {}}, {"hdf5 none", 0, "hdf5", {}}, {"csv", 20, "csv", {}}, {"hdf5", 20, "hdf5", {}}};
  std::vector<nonsep::host::LoadedJob> jobs;
  for (const Configuration& c : configurations) jobs.push_back(make_job(folder, c, side));

  bool ok = true;
  for (int repetition = 0; repetition < repetitions; ++repetition)
    for (std::size_t k = 0; k < configurations.size(); ++k) {
      nonsep::host::RunOptions options;
      options.output_directory = jobs[k].job.output_directory;
      options.threads = threads;
      options.force = true;
      const auto start = std::chrono::steady_clock::now();
      const auto outcome = nonsep::host::run_job(jobs[k], options);
      configurations[k].seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      if (outcome.exit_status != nonsep::host::ExitStatus::success) {
        std::fprintf(stderr, "FAILED: %s ended %s %s\n", configurations[k].name.c_str(),
                     std::string(nonsep::host::to_string(outcome.status)).c_str(), outcome.error.c_str());
        ok = false;
      }
      const auto samples =
          options.output_directory / (configurations[k].format == "hdf5" ? "results.h5" : "trajectory.csv");
      configurations[k].bytes = std::filesystem::exists(samples) ? std::filesystem::file_size(samples) : 0;
    }
  // Pairs of the same `every` (H is evaluated at the samples, so max_abs_relative_energy_error depends on it).
  for (std::size_t k = 1; k < jobs.size(); k += 2)
    if (read_file(jobs[k].job.output_directory / "trajectories.csv") !=
        read_file(jobs[k - 1].job.output_directory / "trajectories.csv")) {
      std::fprintf(stderr, "FAILED: %s and %s have different trajectories.csv\n", configurations[k].name.c_str(),
                   configurations[k - 1].name.c_str());
      ok = false;
    }

  std::printf("paper2d, %zu trajectories, 300 basic steps, %u threads; wall seconds over %d interleaved repetitions\n",
              side * side, threads, repetitions);
  std::printf("%-10s %8s %8s %8s %14s\n", "output", "median", "min", "max", "file bytes");
  for (Configuration& c : configurations) {
    std::sort(c.seconds.begin(), c.seconds.end());
    const std::size_t m = c.seconds.size() / 2;
    const double median = c.seconds.size() % 2 ? c.seconds[m] : 0.5 * (c.seconds[m - 1] + c.seconds[m]);
    std::printf("%-10s %8.3f %8.3f %8.3f %14ju\n", c.name.c_str(), median, c.seconds.front(), c.seconds.back(),
                c.bytes);
  }
  std::filesystem::remove_all(folder);
  return ok ? 0 : 1;
}
