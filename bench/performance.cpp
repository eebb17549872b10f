// The figures of docs/performance.md, each a ratio against a reference measured in the same run (configurations
// interleaved, median of the repetitions), all on the paper's 1D model (paper1d) with the basic step, dt = 1e-4:
//
//   1. one trajectory:       ns per basic step of `nonsep run` (nonsep::host::run_job on paper1d.so, output every
//                            = 0) over the same ChinBasicStep on the same model class compiled in (ModelAdapter).
//                            The host runs chunks through the plugin's integrate() (the fused path, the default);
//   1u.                      the same with the fused path off (RunOptions::fused = false: a plugin call per stage).
//   2. ensemble of 1024:     ns per basic step per trajectory, run_job with 1 thread over the compiled-in batched
//                            loop (ChinBasicStep on one PhaseSpaceBatch of 1024 states); 2u with the fused path off.
//   3. threads:              run_job on a large ensemble, 1 thread over 2 threads (speed-up); 3c the same for
//                            the compiled-in loop cut into the host's blocks, on std::threads: the machine's own
//                            speed-up, which bounds figure 3.
//   4. AD over analytic:     run_job on 1024 trajectories, paper1d_autodiff.so (T and V only, gradients by the
//                            SDK's dual numbers) over paper1d.so (hand-written gradients), 1 thread.
//   6b. output:              run_job on one trajectory writing trajectory.csv every 10^4 steps (with H at each
//                            row) over the same run with every = 0.
//   6c. energy:              the same with H at every step (output.energy_every = 1) over H at start and end.
// Host runs keep the evaluations of H it always does (start and end) and write summary.json (an entry per
// trajectory, then fsync and rename): a fixed cost per run and per trajectory that the step counts amortize, and
// that counts against the host in figures 2 and 3. Every host run's final state is checked bit for bit against the
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
                                 const std::string& plugin, std::size_t count, std::uint64_t steps,
                                 std::uint64_t every = 0, std::uint64_t energy_every = 0) {
  json initial = json::array();
  for (std::size_t b = 0; b < count; ++b) initial.push_back({{"q", {initial_q(b, count)}}, {"p", {0.0}}});
  const json job = {{"model", {{"plugin", plugin}}},
                    {"integrator", {{"scheme", "basic"}}},
                    {"initial", initial},
                    {"time", {{"dt", dt}, {"steps", steps}}},
                    {"output", {{"directory", name + ".out"}, {"every", every}, {"energy_every", energy_every}}}};
  const auto file = folder / (name + ".json");
  std::ofstream(file) << job.dump();
  return nonsep::host::load_job(file);
}

// Seconds for the host to run `job` on `threads` threads; `final_q` receives every trajectory's final q.
// `fused` = false switches the fused path (the plugin's integrate()) off.
double time_host(const nonsep::host::LoadedJob& job, unsigned threads, std::vector<double>& final_q,
                 bool fused = true) {
  nonsep::host::RunOptions options;
  options.output_directory = job.job.output_directory;
  options.threads = threads;
  options.fused = fused;
  const auto start = Clock::now();
  const auto outcome = nonsep::host::run_job(job, options);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.clear();
  for (const auto& trajectory : outcome.trajectories) final_q.push_back(trajectory.final_q.at(0));
  return elapsed.count();
}

// Seconds for the compiled-in loop: ChinBasicStep on one batch of `job`'s states. dt and t2 are taken from the
// loaded job, not from constants: the compiler would fold cbrt(dt) with correctly rounded arithmetic, which can
// differ in the last bit from the run-time cbrt the host uses.
double time_compiled(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const CompiledPaper1D model;
  nonsep::PhaseSpaceBatch x(1, job.job.initial.count);
  std::copy(job.job.initial.q.begin(), job.job.initial.q.end(), x.q().begin());
  std::copy(job.job.initial.p.begin(), job.job.initial.p.end(), x.p().begin());
  nonsep::ChinBasicStep stepper(job.job.integrator.form, job.job.integrator.t2);
  const double step_size = job.job.time.dt;
  const std::uint64_t steps = job.job.time.steps;
  const auto start = Clock::now();
  for (std::uint64_t k = 0; k < steps; ++k) stepper.step(model, x, step_size);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(x.q().begin(), x.q().end());
  return elapsed.count();
}

// Seconds for the compiled-in loop cut as the host cuts an ensemble: blocks of nonsep::host::run_block_size states,
// each stepped to the end on its own, the blocks shared by `threads` std::threads (contiguous halves for 2). No
// plugin, no host: on 2 threads against 1, what the machine itself gives (figure 3c).
double time_compiled_blocks(const nonsep::host::LoadedJob& job, unsigned threads, std::vector<double>& final_q) {
  const CompiledPaper1D model;
  const std::size_t count = job.job.initial.count, block = nonsep::host::run_block_size;
  std::vector<nonsep::PhaseSpaceBatch> blocks;
  for (std::size_t first = 0; first < count; first += block) {
    const std::size_t size = std::min(block, count - first);
    nonsep::PhaseSpaceBatch x(1, size);
    std::copy_n(job.job.initial.q.begin() + static_cast<std::ptrdiff_t>(first), size, x.q().begin());
    std::copy_n(job.job.initial.p.begin() + static_cast<std::ptrdiff_t>(first), size, x.p().begin());
    blocks.push_back(std::move(x));
  }
  const double step_size = job.job.time.dt;
  const std::uint64_t steps = job.job.time.steps;
  const auto run = [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      nonsep::ChinBasicStep stepper(job.job.integrator.form, job.job.integrator.t2);
      for (std::uint64_t k = 0; k < steps; ++k) stepper.step(model, blocks[b], step_size);
    }
  };
  const auto start = Clock::now();
  std::vector<std::thread> workers;
  for (unsigned t = 1; t < threads; ++t)
    workers.emplace_back(run, t * blocks.size() / threads, (t + 1) * blocks.size() / threads);
  run(0, blocks.size() / threads);
  for (auto& worker : workers) worker.join();
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.clear();
  for (const auto& x : blocks) final_q.insert(final_q.end(), x.q().begin(), x.q().end());
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
      std::fprintf(stderr, "%s: the host's final states differ from the compiled-in loop's (%zu, %zu states; "
                   "first q %.17g, %.17g)\n", what, host.size(), compiled.size(), host.empty() ? 0.0 : host[0],
                   compiled.empty() ? 0.0 : compiled[0]);
      agree = false;
    }
  };
  std::vector<double> host_q, compiled_q;

  {  // 1. one trajectory
    const auto steps = scaled(4e6);
    const auto job = make_job(folder, "single", analytic, 1, steps);
    const auto [host, compiled] = interleaved(
        repetitions, [&] { return time_host(job, 1, host_q); }, [&] { return time_compiled(job, compiled_q); });
    check("figure 1", host_q, compiled_q);
    const double per = 1e9 / static_cast<double>(steps);
    figures.push_back({"1. one trajectory: host / compiled in", "ns per basic step", "<= 1.15", host / compiled,
                       host * per, compiled * per});
    const auto [unfused, compiled_again] = interleaved(
        repetitions, [&] { return time_host(job, 1, host_q, false); },
        [&] { return time_compiled(job, compiled_q); });
    check("figure 1u", host_q, compiled_q);
    figures.push_back({"1u. one trajectory: host, fused path off / compiled in", "ns per basic step", "(report)",
                       unfused / compiled_again, unfused * per, compiled_again * per});
  }
  {  // 2. ensemble of 1024, one thread
    const std::size_t count = 1024;
    const auto steps = scaled(4000);
    const auto job = make_job(folder, "ensemble", analytic, count, steps);
    const auto [host, compiled] =
        interleaved(repetitions, [&] { return time_host(job, 1, host_q); },
                    [&] { return time_compiled(job, compiled_q); });
    check("figure 2", host_q, compiled_q);
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back({"2. 1024 trajectories: host (1 thread) / compiled-in batch", "ns per basic step per trajectory",
                       "<= 1.2", host / compiled, host * per, compiled * per});
    const auto [unfused, compiled_again] =
        interleaved(repetitions, [&] { return time_host(job, 1, host_q, false); },
                    [&] { return time_compiled(job, compiled_q); });
    check("figure 2u", host_q, compiled_q);
    figures.push_back({"2u. 1024 trajectories: host (1 thread), fused path off / compiled-in batch",
                       "ns per basic step per trajectory", "(report)", unfused / compiled_again, unfused * per,
                       compiled_again * per});
  }
  {  // 3. two threads over one, large ensemble
    const std::size_t count = 8192;
    const auto steps = scaled(2000);
    const auto job = make_job(folder, "threads", analytic, count, steps);
    std::vector<double> two_q;
    const auto [one, two] = interleaved(
        repetitions, [&] { return time_host(job, 1, host_q); }, [&] { return time_host(job, 2, two_q); });
    if (host_q != two_q) {
      std::fprintf(stderr, "figure 3: 2 threads give other final states than 1\n");
      agree = false;
    }
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back({"3. 8192 trajectories: 1 thread / 2 threads (speed-up)", "ns per basic step per trajectory",
                       ">= 1.8", one / two, two * per, one * per});
    std::vector<double> compiled_two_q;
    const auto [compiled_one, compiled_two] =
        interleaved(repetitions, [&] { return time_compiled_blocks(job, 1, compiled_q); },
                    [&] { return time_compiled_blocks(job, 2, compiled_two_q); });
    check("figure 3c (1 thread)", host_q, compiled_q);
    check("figure 3c (2 threads)", host_q, compiled_two_q);
    figures.push_back({"3c. 8192 trajectories, compiled in: 1 thread / 2 threads (the machine's own speed-up)",
                       "ns per basic step per trajectory", "(ceiling of 3)", compiled_one / compiled_two,
                       compiled_two * per, compiled_one * per});
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
  {  // 6b. output every 10^4 steps over no output, one trajectory
    const auto steps = scaled(4e6);
    const auto job_output = make_job(folder, "output", analytic, 1, steps, 10000);
    const auto job_silent = make_job(folder, "silent", analytic, 1, steps, 0);
    std::vector<double> silent_q;
    const auto [output, silent] = interleaved(
        repetitions, [&] { return time_host(job_output, 1, host_q); },
        [&] { return time_host(job_silent, 1, silent_q); });
    check("figure 6b", host_q, silent_q);
    const double per = 1e9 / static_cast<double>(steps);
    figures.push_back({"6b. one trajectory: output every 10^4 steps / no output", "ns per basic step", "~ 1",
                       output / silent, output * per, silent * per});
  }
  {  // 6c. H at every step (energy_every = 1, the old default) over H at start and end only
    const auto steps = scaled(4e6);
    const auto job_energy = make_job(folder, "energy", analytic, 1, steps, 0, 1);
    const auto job_silent = make_job(folder, "silent", analytic, 1, steps, 0, 0);
    std::vector<double> silent_q;
    const auto [energy, silent] = interleaved(
        repetitions, [&] { return time_host(job_energy, 1, host_q); },
        [&] { return time_host(job_silent, 1, silent_q); });
    check("figure 6c", host_q, silent_q);
    const double per = 1e9 / static_cast<double>(steps);
    figures.push_back({"6c. one trajectory: H at every step / H at start and end", "ns per basic step",
                       "(informative)", energy / silent, energy * per, silent * per});
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
