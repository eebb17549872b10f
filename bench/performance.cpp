// The figures of docs/performance.md, each a ratio against a reference measured in the same run (configurations
// interleaved, median of the repetitions), all on the paper's 1D model (paper1d) with the basic step, dt = 1e-4:
//
//   1. one trajectory:       ns per basic step of `nonsep run` (nonsep::host::run_job on paper1d.so, output every
//                            = 0) over the same ChinBasicStep on the same model class compiled in (ModelAdapter).
//   2. ensemble of 1024:     ns per basic step per trajectory, run_job with 1 thread over the compiled-in batched
//                            loop (ChinBasicStep on one PhaseSpaceBatch of 1024 states).
//   3. threads:              run_job on a large ensemble, 1 thread over 2 threads (speed-up).
//   4. AD over analytic:     run_job on 1024 trajectories, paper1d_autodiff.so (T and V only, gradients by the
//                            SDK's dual numbers) over paper1d.so (hand-written gradients), 1 thread.
// Host runs keep the evaluations of H it always does (start and end) and write summary.json; the step counts make
// those a negligible part of the time. Every host run's final state is checked bit for bit against the
// compiled-in loop, so a faster but wrong path cannot pass.
//
// Usage: nonsep_bench_performance [--smoke] [--repetitions N] [--scale X]
//   --smoke         a few repetitions of short runs (< 10 s; the ctest bench.performance.smoke)
//   --repetitions   timed repetitions per configuration (default 7; smoke 3)
//   --scale         multiplies every run's step count (default 1; smoke 0.05)
// Exit status 1 when a host run disagrees with the compiled-in loop; the figures' targets are reported, not
// enforced (timings on a shared machine are not a test).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "nonsep/core/chin_basic_step.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/runner.hpp"
#include "paper1d/paper1d.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;
using CompiledPaper1D = nonsep::sdk::ModelAdapter<Paper1D>;

constexpr double dt = 1e-4;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

// Initial states: q spread over [0.2, 1.8], p = 0 (closed orbits of the paper's Fig. 1).
double initial_q(std::size_t b, std::size_t count) {
  return 0.2 + 1.6 * static_cast<double>(b) / static_cast<double>(count);
}

// A paper1d job of `count` trajectories and `steps` basic steps, written to `folder`/`name`.json and loaded.
nonsep::host::LoadedJob make_job(const std::filesystem::path& folder, const std::string& name,
                                 const std::string& plugin, std::size_t count, std::uint64_t steps) {
  json initial = json::array();
  for (std::size_t b = 0; b < count; ++b) initial.push_back({{"q", {initial_q(b, count)}}, {"p", {0.0}}});
  const json job = {{"model", {{"plugin", plugin}}},
                    {"integrator", {{"scheme", "basic"}}},
                    {"initial", initial},
                    {"time", {{"dt", dt}, {"steps", steps}}},
                    {"output", {{"directory", name + ".out"}, {"every", 0}}}};
  const auto file = folder / (name + ".json");
  std::ofstream(file) << job.dump();
  return nonsep::host::load_job(file);
}

// Seconds for the host to run `job` on `threads` threads; `final_q` receives every trajectory's final q.
double time_host(const nonsep::host::LoadedJob& job, unsigned threads, std::vector<double>& final_q) {
  nonsep::host::RunOptions options;
  options.output_directory = job.job.output_directory;
  options.threads = threads;
  const auto start = Clock::now();
  const auto outcome = nonsep::host::run_job(job, options);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.clear();
  for (const auto& trajectory : outcome.summary["trajectories"])
    final_q.push_back(trajectory["final"]["q"][0].get<double>());
  return elapsed.count();
}

// Seconds for the compiled-in loop: ChinBasicStep on one batch of `count` states.
double time_compiled(std::size_t count, std::uint64_t steps, std::vector<double>& final_q) {
  const CompiledPaper1D model;
  nonsep::PhaseSpaceBatch x(1, count);
  for (std::size_t b = 0; b < count; ++b) x.q()[b] = initial_q(b, count);
  nonsep::ChinBasicStep stepper;
  const auto start = Clock::now();
  for (std::uint64_t k = 0; k < steps; ++k) stepper.step(model, x, dt);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(x.q().begin(), x.q().end());
  return elapsed.count();
}

struct Figure {
  std::string name, unit, target;
  double value;     // the ratio
  double measured;  // of the configuration, in `unit`
  double reference; // of the reference, in `unit`
};

// Runs `a` and `b` interleaved `repetitions` times (after one warm-up each) and returns their median times.
std::pair<double, double> interleaved(int repetitions, const std::function<double()>& a,
                                      const std::function<double()>& b) {
  a();
  b();
  std::vector<double> ta, tb;
  for (int r = 0; r < repetitions; ++r) {
    ta.push_back(a());
    tb.push_back(b());
  }
  return {median(ta), median(tb)};
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int repetitions = 0;
  double scale = 0.0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke") smoke = true;
    else if (arg == "--repetitions" && i + 1 < argc) repetitions = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--scale" && i + 1 < argc) scale = std::atof(argv[++i]);
    else {
      std::fprintf(stderr, "usage: %s [--smoke] [--repetitions N] [--scale X]\n", argv[0]);
      return 2;
    }
  }
  if (repetitions == 0) repetitions = smoke ? 3 : 7;
  if (scale <= 0.0) scale = smoke ? 0.05 : 1.0;
  auto scaled = [&](double steps) { return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(steps * scale)); };

  const auto folder = std::filesystem::temp_directory_path() /
                      ("nonsep_bench_performance_" + std::to_string(static_cast<long>(::getpid())));
  std::filesystem::create_directories(folder);
  const std::string analytic = std::string(NONSEP_BUILD_PLUGIN_DIR) + "/paper1d.so";
  const std::string automatic = std::string(NONSEP_BENCH_PLUGIN_DIR) + "/paper1d_autodiff.so";

  std::vector<Figure> figures;
  bool agree = true;
  auto check = [&](const char* what, const std::vector<double>& host, const std::vector<double>& compiled) {
    if (host != compiled) {
      std::fprintf(stderr, "%s: the host's final states differ from the compiled-in loop's\n", what);
      agree = false;
    }
  };
  std::vector<double> host_q, compiled_q;

  {  // 1. one trajectory
    const auto steps = scaled(4e6);
    const auto job = make_job(folder, "single", analytic, 1, steps);
    const auto [host, compiled] = interleaved(
        repetitions, [&] { return time_host(job, 1, host_q); }, [&] { return time_compiled(1, steps, compiled_q); });
    check("figure 1", host_q, compiled_q);
    const double per = 1e9 / static_cast<double>(steps);
    figures.push_back({"1. one trajectory: host / compiled in", "ns per basic step", "<= 1.15", host / compiled,
                       host * per, compiled * per});
  }
  {  // 2. ensemble of 1024, one thread
    const std::size_t count = 1024;
    const auto steps = scaled(4000);
    const auto job = make_job(folder, "ensemble", analytic, count, steps);
    const auto [host, compiled] =
        interleaved(repetitions, [&] { return time_host(job, 1, host_q); },
                    [&] { return time_compiled(count, steps, compiled_q); });
    check("figure 2", host_q, compiled_q);
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back({"2. 1024 trajectories: host (1 thread) / compiled-in batch", "ns per basic step per trajectory",
                       "<= 1.2", host / compiled, host * per, compiled * per});
  }
  {  // 3. two threads over one, large ensemble
    const std::size_t count = 16384;
    const auto steps = scaled(400);
    const auto job = make_job(folder, "threads", analytic, count, steps);
    std::vector<double> two_q;
    const auto [one, two] = interleaved(
        repetitions, [&] { return time_host(job, 1, host_q); }, [&] { return time_host(job, 2, two_q); });
    if (host_q != two_q) {
      std::fprintf(stderr, "figure 3: 2 threads give other final states than 1\n");
      agree = false;
    }
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back({"3. 16384 trajectories: 1 thread / 2 threads (speed-up)", "ns per basic step per trajectory",
                       ">= 1.8", one / two, two * per, one * per});
  }
  {  // 4. AD over analytic gradients, through the host
    const std::size_t count = 1024;
    const auto steps = scaled(4000);
    const auto job_automatic = make_job(folder, "automatic", automatic, count, steps);
    const auto job_analytic = make_job(folder, "analytic", analytic, count, steps);
    std::vector<double> automatic_q;
    const auto [ad, exact] = interleaved(
        repetitions, [&] { return time_host(job_automatic, 1, automatic_q); },
        [&] { return time_host(job_analytic, 1, host_q); });
    for (std::size_t b = 0; b < count; ++b)
      if (!(std::abs(automatic_q[b] - host_q[b]) < 1e-9)) {
        std::fprintf(stderr, "figure 4: AD and analytic gradients give different orbits (state %zu)\n", b);
        agree = false;
        break;
      }
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back({"4. 1024 trajectories: AD plugin / analytic plugin", "ns per basic step per trajectory",
                       "<= 2", ad / exact, ad * per, exact * per});
  }
  std::filesystem::remove_all(folder);

  std::printf("paper1d, basic step, dt = %g; median of %d interleaved repetitions%s; %u hardware threads\n", dt,
              repetitions, smoke ? " (smoke run: short, not for the record)" : "",
              std::thread::hardware_concurrency());
  std::printf("| figure | ratio | target | measured | reference | unit |\n|---|---|---|---|---|---|\n");
  for (const auto& f : figures)
    std::printf("| %s | %.3f | %s | %.4g | %.4g | %s |\n", f.name.c_str(), f.value, f.target.c_str(), f.measured,
                f.reference, f.unit.c_str());
  std::printf("final states: host = compiled in (bit for bit), 2 threads = 1 thread, AD ~ analytic: %s\n",
              agree ? "yes" : "NO");
  return agree ? 0 : 1;
}
