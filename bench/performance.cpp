// The figures of docs/performance.md, each a ratio measured in one run of this program (configurations
// interleaved, median of the repetitions, the spread of the per-repetition ratios reported), all on the paper's 1D
// model (paper1d) with the basic step, dt = 1e-4. The reference is the physical limit: the basic step written out
// by hand (bench/hand_written.hpp: nine stages, gradients inline, no Integrator, no batch types, no plugin),
// compiled with the same flags as the host.
//
//   1. one trajectory:     ns per basic step of `nonsep run` (nonsep::host::run_job on paper1d.so, no output: the
//                          plugin's kernel, chosen at run time) over the hand-written loop on one (q, p). 1a: the
//                          floor of an evaluation-only plugin boundary (abi_floor.hpp: the hand-written stages
//                          calling paper1d_minimal.so, a plugin without the SDK and without kernels, for every
//                          gradient) over the same loop: why kernels exist; 1h: the host over that floor; 1r: the
//                          control, the gradients called through function pointers by value (registers), which tells
//                          the cost of a call from that of passing numbers through memory. 1c: the core's
//                          ChinBasicStep compiled in (step_n), over the hand-written loop.
//   1t, 1m, 1m4. compositions: ns per step of run_job with triplet 4/3, mpe 4/3 and mpe 4 on one trajectory over
//                          the hand-written step composed by hand (hand_written_triplet_run, hand_written_mpe_run).
//   2. 1024 trajectories:  ns per basic step per trajectory, run_job on 1 thread over the faster of two hand-written
//                          loops over 1024 states (state by state; stage by stage) compiled -march=native
//                          (hand_written_native.cpp) whatever this build's flags: the portable build's kernels
//                          chosen at run time against the machine's own limit (figure 2n in a NONSEP_NATIVE build).
//                          2p: over the same loops compiled with this build's flags. 2a, 2h: the floor of the
//                          evaluation-only boundary in the host's blocks of 256, as 1a and 1h. 2c: ChinBasicStep on
//                          one batch over the loops with this build's flags.
//   3. threads:            1024 trajectories, run_job on 1 thread over 2 threads (speed-up); 3b the same while a
//                          child process of this program spins on one core; 3c the hand-written loop cut into the
//                          host's blocks on std::threads, 1 over 2: what the machine itself gives two threads.
//   7. coupled3d:          the same as 1 and 2 on a 3-D coupled model with a parameter (coupled3d.hpp), against its
//                          own hand-written loops (one state in local arrays; 1024 stage by stage, -march=native).
//   8. tangent map:        ns per basic step per trajectory of run_job with one Lyapunov vector (analysis.lyapunov,
//                          renormalised every 10 steps) on 1024 trajectories, 1 thread, over the hand-written tangent
//                          step (hand_written_tangent_run, same flags); 8h: that hand-written tangent step over the
//                          hand-written plain step (what the tangent map costs at the limit). The exponents must
//                          agree to 1e-9 relative.
//   4. AD over analytic:   run_job on 1024 trajectories, paper1d_autodiff.so (T and V only, gradients by the
//                          SDK's dual numbers) over paper1d.so (hand-written gradients), 1 thread.
//   6b. output:            run_job on one trajectory writing trajectory.csv every 10^4 steps (with H at each
//                          row) over the same run with every = 0.
//   6c. energy:            the same with H at every step (output.energy_every = 1) over H at start and end.
// Host runs keep the evaluations of H they always do (start and end) and write summary.json and trajectories.csv:
// a fixed cost per run and per trajectory that the step counts amortize, and that counts against the host.
// Every host run's final states are checked against the hand-written loop: bit for bit when neither the build nor
// the kernel can contract into fused multiply-adds (no __FMA__, kernel x86-64: NONSEP_INSTRUCTION_SET=baseline),
// else to 1e-9 (the plugin and this program may fuse different pairs) and the output says which; 2 threads must
// give the states of 1 thread bit for bit.
//
// Usage: nonsep_bench_performance [--smoke] [--repetitions N] [--scale X] [--only F]
//   --smoke         a few repetitions of short runs (< 10 s; the ctest bench.performance.smoke)
//   --repetitions   timed repetitions per configuration (default 7; smoke 3)
//   --scale         multiplies every run's step count (default 1; smoke 0.05)
//   --only          one group of figures: 1 (1, 1a, 1h, 1r, 1c), 1t (1t, 1m, 1m4), 2 (2, 2p, 2a, 2h, 2c), 3 (3, 3b,
//                   3c), 4, 6b, 6c, 7 (7, 7e) or 8 (8, 8h) (e.g. to run one under callgrind)
// Exit status 1 when a check fails; the figures' targets are reported, not enforced (timings on a shared machine
// are not a test).
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "abi_floor.hpp"
#include "coupled3d.hpp"
#include "hand_written.hpp"
#include "hand_written_native.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/multi_product_expansion.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "paper1d/paper1d.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;
using CompiledPaper1D = nonsep::sdk::ModelAdapter<Paper1D>;

constexpr double dt = 1e-4;

// The references' arrays start on a cache line, as the host's do (nonsep/core/base/aligned_allocator.hpp): with the
// wide vectors of a native build, arrays that straddle lines would make the limit slower than it is.
using Doubles = nonsep::AlignedDoubles;
Doubles copy_of(const std::vector<double>& values) { return Doubles(values.begin(), values.end()); }

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
                                 std::uint64_t every = 0, std::uint64_t energy_every = 0,
                                 const json& integrator = {{"scheme", "basic"}}, const json& analysis = nullptr) {
  json initial = json::array();
  const bool three = plugin.find("coupled3d") != std::string::npos;
  for (std::size_t b = 0; b < count; ++b) {
    const double q = initial_q(b, count);
    initial.push_back(three ? json{{"q", {q, 0.5 * q, -0.3 * q}}, {"p", {0.0, 0.1, -0.1}}}
                            : json{{"q", {q}}, {"p", {0.0}}});
  }
  json job = {{"model", {{"plugin", plugin}}},
              {"integrator", integrator},
              {"initial", initial},
              {"time", {{"dt", dt}, {"steps", steps}}},
              {"output", {{"directory", name + ".out"}, {"every", every}, {"energy_every", energy_every}}}};
  if (!analysis.is_null()) job["analysis"] = analysis;
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
  for (const auto& trajectory : outcome.trajectories) final_q.push_back(trajectory.final_q.at(0));
  return elapsed.count();
}

// Seconds for the hand-written loop on `job`'s states: one (q, p) through the scalar loop when the job has one
// trajectory, else all of them through both loops over states (the faster one's time). dt and t2 are taken from the
// loaded job, not from constants, so that cbrt runs at run time as in the host (a compile-time cbrt may round
// differently).
double time_hand_written(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p), g(q.size());
  const std::uint64_t steps = job.job.run().time.steps;
  const auto start = Clock::now();
  if (q.size() == 1)
    bench::hand_written_run(c, q[0], p[0], steps);
  else
    bench::hand_written_run(c, q.data(), p.data(), g.data(), q.size(), steps);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(q.begin(), q.end());
  if (q.size() == 1) return elapsed.count();
  // More than one state: the stage-by-stage loop too, and the faster of the two is the limit. Both must agree.
  Doubles q2 = copy_of(job.job.initial.q), p2 = copy_of(job.job.initial.p);
  const auto start2 = Clock::now();
  bench::hand_written_run_staged(c, q2.data(), p2.data(), g.data(), q2.size(), steps);
  const std::chrono::duration<double> elapsed2 = Clock::now() - start2;
  if (q2 != q) final_q.clear();  // fails the caller's check
  return std::min(elapsed.count(), elapsed2.count());
}

// Seconds for the hand-written composition of `job`'s scheme (triplet 4/3 or mpe of its order) on its one state.
double time_hand_written_composition(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const auto& run = job.job.run();
  double q = job.job.initial.q.at(0), p = job.job.initial.p.at(0);
  const auto start = Clock::now();
  if (run.integrator.scheme == "triplet")
    bench::hand_written_triplet_run(run.time.dt, std::get<nonsep::ChinOptions>(run.integrator.options).t2, q, p,
                                    run.time.steps);
  else
    bench::hand_written_mpe_run(run.time.dt, std::get<nonsep::ChinOptions>(run.integrator.options).t2,
                                nonsep::MultiProductExpansion<>::weights_for(static_cast<int>(std::lround(
                                    std::get<nonsep::ChinOptions>(run.integrator.options).order.value() * 1.5))),
                                q, p, run.time.steps);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(1, q);
  return elapsed.count();
}

// Seconds for the hand-written loops over `job`'s states compiled -march=native (hand_written_native.cpp): the
// faster of the two, which must agree.
double time_hand_written_native(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p), g(q.size());
  Doubles q2 = q, p2 = p;
  const std::uint64_t steps = job.job.run().time.steps;
  const auto start = Clock::now();
  bench::native_run(c, q.data(), p.data(), g.data(), q.size(), steps);
  const auto middle = Clock::now();
  bench::native_run_staged(c, q2.data(), p2.data(), g.data(), q2.size(), steps);
  const std::chrono::duration<double> first = middle - start, second = Clock::now() - middle;
  final_q.assign(q.begin(), q.end());
  for (std::size_t b = 0; b < q.size(); ++b)
    if (!(std::abs(q[b] - q2[b]) < 1e-9)) final_q.clear();  // fails the caller's check
  return std::min(first.count(), second.count());
}

// Seconds for the hand-written basic step on coupled3d (coupled3d.hpp) on `job`'s states: the local-array loop for
// one state, the stage-by-stage loop compiled -march=native for more.
double time_hand_written_coupled3d(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p), g(q.size());
  const std::uint64_t steps = job.job.run().time.steps;
  const double coupling = 0.2;
  const auto start = Clock::now();
  if (q.size() == 3)
    bench::coupled3d_run(c, coupling, q.data(), p.data(), steps);
  else
    bench::native_coupled3d_run_staged(c, coupling, q.data(), p.data(), g.data(), q.size() / 3, steps);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.clear();
  for (std::size_t i = 0; i < q.size(); i += 3) final_q.push_back(q[i]);
  return elapsed.count();
}

// Seconds for the hand-written tangent step on `job`'s states, one Lyapunov vector each, (1, 1/2) normalised as the
// host starts it, renormalised every `renormalize_every` steps; `final_q` receives the final q and `exponents` the
// largest Lyapunov exponents.
double time_hand_written_tangent(const nonsep::host::LoadedJob& job, std::uint64_t renormalize_every,
                                 std::vector<double>& final_q, std::vector<double>& exponents) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p);
  const double norm = std::sqrt(1.25);
  Doubles dq(q.size(), 1.0 / norm), dp(q.size(), 0.5 / norm), log_stretch(q.size(), 0.0);
  const std::uint64_t steps = job.job.run().time.steps;
  const auto start = Clock::now();
  bench::hand_written_tangent_run(c, q.data(), p.data(), dq.data(), dp.data(), log_stretch.data(), q.size(), steps,
                                  renormalize_every);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(q.begin(), q.end());
  exponents.clear();
  for (double stretch : log_stretch)
    exponents.push_back(stretch / (static_cast<double>(steps) * job.job.run().time.dt));
  return elapsed.count();
}

// Seconds for the core's ChinBasicStep on one batch of `job`'s states, the model compiled in (ModelAdapter).
double time_core(const nonsep::host::LoadedJob& job, std::vector<double>& final_q) {
  const CompiledPaper1D model;
  nonsep::PhaseSpaceBatch x(1, job.job.initial.count);
  std::copy(job.job.initial.q.begin(), job.job.initial.q.end(), x.q().begin());
  std::copy(job.job.initial.p.begin(), job.job.initial.p.end(), x.p().begin());
  nonsep::ChinBasicStep stepper(job.job.run().integrator.form,
                                std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  const double step_size = job.job.run().time.dt;
  const std::uint64_t steps = job.job.run().time.steps;
  const auto start = Clock::now();
  stepper.step_n(model, x, step_size, steps);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(x.q().begin(), x.q().end());
  return elapsed.count();
}

// Seconds for the floor of the evaluation-only boundary (abi_floor.hpp) on `job`'s states: the hand-written staged
// loop calling paper1d_minimal.so per stage, in the host's blocks; with `by_value`, one trajectory only, the control
// that calls the scalar gradients by value.
double time_abi_floor(const nonsep::host::LoadedJob& job, const bench::MinimalPlugin& plugin, bool by_value,
                      std::vector<double>& final_q) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p);
  const std::uint64_t steps = job.job.run().time.steps;
  const auto start = Clock::now();
  if (by_value)
    bench::register_call_run(c, plugin, q.at(0), p.at(0), steps);
  else
    bench::abi_floor_run_blocks(c, plugin, q, p, nonsep::host::run_block_size, steps);
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(q.begin(), q.end());
  return elapsed.count();
}

// Seconds for the hand-written loop cut as the host cuts an ensemble: blocks of nonsep::host::run_block_size
// states, each stepped to the end on its own, the blocks shared by `threads` std::threads (contiguous parts).
// Stage by stage, as the host steps: the fused loop over a block of 256 took 11.5 ns per state and step on one
// thread here against 3.7 staged, and gave an implausible 2.9x "speed-up" on two cores.
double time_hand_written_blocks(const nonsep::host::LoadedJob& job, unsigned threads, std::vector<double>& final_q) {
  const bench::HandWrittenStep c(job.job.run().time.dt,
                                 std::get<nonsep::ChinOptions>(job.job.run().integrator.options).t2);
  Doubles q = copy_of(job.job.initial.q), p = copy_of(job.job.initial.p), g(q.size());
  const std::size_t count = q.size(), block = nonsep::host::run_block_size;
  const std::size_t blocks = (count + block - 1) / block;
  const std::uint64_t steps = job.job.run().time.steps;
  const auto run = [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) {
      const std::size_t first = b * block, size = std::min(block, count - first);
      bench::hand_written_run_staged(c, q.data() + first, p.data() + first, g.data() + first, size, steps);
    }
  };
  const auto start = Clock::now();
  std::vector<std::thread> workers;
  for (unsigned t = 1; t < threads; ++t) workers.emplace_back(run, t * blocks / threads, (t + 1) * blocks / threads);
  run(0, blocks / threads);
  for (auto& worker : workers) worker.join();
  const std::chrono::duration<double> elapsed = Clock::now() - start;
  final_q.assign(q.begin(), q.end());
  return elapsed.count();
}

// A child process spinning on one core for as long as it lives (figure 3b); killed by the destructor.
class BusyCore {
 public:
  BusyCore() : pid_(::fork()) {
    if (pid_ == 0) {
      volatile unsigned long spin = 0;
      for (;;) spin = spin + 1;
    }
  }
  ~BusyCore() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  BusyCore(const BusyCore&) = delete;
  BusyCore& operator=(const BusyCore&) = delete;
  bool running() const { return pid_ > 0; }

 private:
  pid_t pid_;
};

struct Figure {
  std::string name, unit, target;
  double value;      // median measured / median reference
  double low, high;  // smallest and largest per-repetition ratio
  double measured;   // median of the configuration, in `unit`
  double reference;  // median of the reference, in `unit`
};

// Runs every configuration once (warm-up), then all of them in turn `repetitions` times; their times, in seconds,
// one vector per configuration.
std::vector<std::vector<double>> interleaved(int repetitions, const std::vector<std::function<double()>>& runs) {
  for (const auto& run : runs) run();
  std::vector<std::vector<double>> times(runs.size());
  for (int r = 0; r < repetitions; ++r)
    for (std::size_t k = 0; k < runs.size(); ++k) times[k].push_back(runs[k]());
  return times;
}
std::pair<std::vector<double>, std::vector<double>> interleaved(int repetitions, const std::function<double()>& a,
                                                                const std::function<double()>& b) {
  auto times = interleaved(repetitions, {a, b});
  return {std::move(times[0]), std::move(times[1])};
}

// The figure of times `a` (measured) over `b` (reference), `per` converting seconds into `unit`.
Figure figure(std::string name, std::string target, std::string unit, const std::vector<double>& a,
              const std::vector<double>& b, double per) {
  std::vector<double> ratios;
  for (std::size_t r = 0; r < a.size(); ++r) ratios.push_back(a[r] / b[r]);
  const auto [low, high] = std::minmax_element(ratios.begin(), ratios.end());
  return {std::move(name), std::move(unit), std::move(target), median(a) / median(b), *low,
          *high,           median(a) * per, median(b) * per};
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int repetitions = 0;
  double scale = 0.0;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke")
      smoke = true;
    else if (arg == "--repetitions" && i + 1 < argc)
      repetitions = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--scale" && i + 1 < argc)
      scale = std::atof(argv[++i]);
    else if (arg == "--only" && i + 1 < argc)
      only = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--smoke] [--repetitions N] [--scale X] [--only F]\n", argv[0]);
      return 2;
    }
  }
  if (repetitions == 0) repetitions = smoke ? 3 : 7;
  if (scale <= 0.0) scale = smoke ? 0.05 : 1.0;
  auto scaled = [&](double steps) { return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(steps * scale)); };

#if defined(__AVX512F__)
  const char* simd = "AVX-512 (-march)";
  constexpr bool native = true;
#elif defined(__AVX2__)
  const char* simd = "AVX2 (-march)";
  constexpr bool native = true;
#else
  const char* simd = "SSE2 (portable x86-64)";
  constexpr bool native = false;
#endif
  const auto folder = std::filesystem::temp_directory_path() /
                      ("nonsep_bench_performance_" + std::to_string(static_cast<long>(::getpid())));
  std::filesystem::create_directories(folder);
  const std::string analytic = std::string(NONSEP_BUILD_PLUGIN_DIR) + "/paper1d.so";
  const std::string automatic = std::string(NONSEP_BENCH_PLUGIN_DIR) + "/paper1d_autodiff.so";
  const bench::MinimalPlugin minimal(std::string(NONSEP_BENCH_PLUGIN_DIR) + "/paper1d_minimal.so");

  std::vector<Figure> figures;
  bool agree = true;
  // The kernel the host runs paper1d with: the baseline computes what this program does bit for bit (without FMA);
  // a wider instruction set may fuse multiplications and additions.
  const nonsep::host::Plugin paper1d = nonsep::host::load_plugin(analytic, folder);
  const std::string kernel = paper1d.kernels().chosen ? paper1d.kernels().chosen_name() : "none (evaluation path)";
#ifdef __FMA__
  constexpr bool fma_build = true;  // the plugin and the hand-written loop may fuse different pairs
#else
  constexpr bool fma_build = false;
#endif
  const bool exact_expected = !fma_build && (kernel == "x86-64" || !paper1d.kernels().chosen);
  bool all_exact = true;
  // Final q of a host run against the hand-written loop's: equal bit for bit, or (FMA builds) within 1e-9.
  auto check = [&](const char* what, const std::vector<double>& host, const std::vector<double>& reference) {
    bool close = host.size() == reference.size();
    for (std::size_t b = 0; close && b < host.size(); ++b) close = std::abs(host[b] - reference[b]) < 1e-9;
    const bool exact = host == reference;
    all_exact = all_exact && exact;
    if (exact || (close && !exact_expected)) return;
    std::fprintf(stderr,
                 "%s: the host's final states differ from the hand-written loop's (%zu, %zu states; "
                 "first q %.17g, %.17g)\n",
                 what, host.size(), reference.size(), host.empty() ? 0.0 : host[0],
                 reference.empty() ? 0.0 : reference[0]);
    agree = false;
  };
  std::vector<double> host_q, reference_q, core_q;
  auto wanted = [&](const char* group) { return only.empty() || only == group; };

  if (wanted("1")) {  // 1. one trajectory
    const auto steps = scaled(4e6);
    const auto job = make_job(folder, "single", analytic, 1, steps);
    const double per = 1e9 / static_cast<double>(steps);
    std::vector<double> floor_q, control_q;
    const auto t = interleaved(
        repetitions,
        {[&] { return time_host(job, 1, host_q); }, [&] { return time_hand_written(job, reference_q); },
         [&] { return time_abi_floor(job, minimal, false, floor_q); },
         [&] { return time_abi_floor(job, minimal, true, control_q); }, [&] { return time_core(job, core_q); }});
    check("figure 1", host_q, reference_q);
    check("figure 1a", floor_q, reference_q);
    check("figure 1r", control_q, reference_q);
    check("figure 1c", core_q, reference_q);
    const char* unit = "ns per basic step";
    figures.push_back(figure("1. one trajectory: host (kernel) / hand-written", "<= 1.15", unit, t[0], t[1], per));
    figures.push_back(
        figure("1a. one trajectory: ABI floor / hand-written", "(the floor of 1)", unit, t[2], t[1], per));
    figures.push_back(
        figure("1h. one trajectory: host / ABI floor (what the host adds)", "(report)", unit, t[0], t[2], per));
    figures.push_back(figure("1r. one trajectory: gradients called by value / hand-written (control)", "(report)", unit,
                             t[3], t[1], per));
    figures.push_back(
        figure("1c. one trajectory: ChinBasicStep compiled in / hand-written", "(report)", unit, t[4], t[1], per));
  }
  if (wanted("1t")) {  // 1t, 1m, 1m4. one trajectory, triplet 4/3, mpe 4/3 and mpe 4 against hand-written compositions
    for (const auto& [name, integrator, basic_steps] :
         {std::tuple{"1t. one trajectory, triplet 4/3: host / hand-written composition",
                     json{{"scheme", "triplet"}, {"order", "4/3"}}, 3.0},
          std::tuple{"1m. one trajectory, mpe 4/3: host / hand-written expansion",
                     json{{"scheme", "mpe"}, {"order", "4/3"}}, 3.0},
          std::tuple{"1m4. one trajectory, mpe 4 (6 terms): host / hand-written expansion",
                     json{{"scheme", "mpe"}, {"order", "4"}}, 21.0}}) {
      const auto steps = scaled(4e6 / basic_steps);
      const auto job = make_job(folder, "composition", analytic, 1, steps, 0, 0, integrator);
      const auto t = interleaved(repetitions, {[&] { return time_host(job, 1, host_q); },
                                               [&] { return time_hand_written_composition(job, reference_q); }});
      check(name, host_q, reference_q);
      figures.push_back(figure(name, "<= 1.2", "ns per step", t[0], t[1], 1e9 / static_cast<double>(steps)));
    }
  }
  if (wanted("7")) {  // 7. coupled3d: one trajectory and 1024, against its hand-written loops
    const std::string coupled3d = std::string(NONSEP_BENCH_PLUGIN_DIR) + "/coupled3d.so";
    for (const auto& [name, target, count, steps] :
         {std::tuple{"7. coupled3d, one trajectory: host (kernel) / hand-written", "within 10% of figure 1",
                     std::size_t{1}, scaled(2e6)},
          std::tuple{"7e. coupled3d, 1024 trajectories: host (1 thread, kernel) / hand-written -march=native",
                     "within 10% of figure 2", std::size_t{1024}, scaled(10000)}}) {
      const auto job = make_job(folder, "coupled3d", coupled3d, count, steps);
      const auto t = interleaved(repetitions, {[&] { return time_host(job, 1, host_q); },
                                               [&] { return time_hand_written_coupled3d(job, reference_q); }});
      if (exact_expected) check(name, host_q, reference_q);  // else fused and chaotic orbits: not comparable
      figures.push_back(figure(name, target, count == 1 ? "ns per basic step" : "ns per basic step per trajectory",
                               t[0], t[1], 1e9 / static_cast<double>(steps * count)));
    }
  }
  if (wanted("8")) {  // 8, 8h. one Lyapunov vector, 1024 trajectories, against the hand-written tangent step
    const std::uint64_t renormalize_every = 10, steps = scaled(5000) / renormalize_every * renormalize_every;
    const std::size_t count = 1024;
    const auto job = make_job(folder, "tangent", analytic, count, steps, 0, 0, {{"scheme", "basic"}},
                              {{"lyapunov", {{"vectors", 1}, {"renormalize_every", renormalize_every}}}});
    std::vector<double> host_exponents, reference_exponents, plain_q;
    const auto t = interleaved(
        repetitions,
        {[&] {
           nonsep::host::RunOptions options;
           options.output_directory = job.job.output_directory;
           options.threads = 1;
           const auto start = Clock::now();
           const auto outcome = nonsep::host::run_job(job, options);
           const std::chrono::duration<double> elapsed = Clock::now() - start;
           host_q.clear();
           host_exponents.clear();
           for (const auto& trajectory : outcome.trajectories) {
             host_q.push_back(trajectory.final_q.at(0));
             // The job's one indicator is lyapunov with one vector: its first column is lyapunov0.
             host_exponents.push_back(trajectory.indicators.empty() ? std::nan("") : trajectory.indicators.at(0));
           }
           return elapsed.count();
         },
         [&] { return time_hand_written_tangent(job, renormalize_every, reference_q, reference_exponents); },
         [&] { return time_hand_written(job, plain_q); }});
    check("8. tangent map", host_q, reference_q);
    bool close = host_exponents.size() == reference_exponents.size();
    for (std::size_t b = 0; close && b < host_exponents.size(); ++b)
      close = std::abs(host_exponents[b] - reference_exponents[b]) <=
              1e-9 * std::max(1.0, std::abs(reference_exponents[b]));
    if (!close) {
      std::fprintf(stderr, "8. tangent map: the host's Lyapunov exponents differ from the hand-written ones\n");
      agree = false;
    }
    const double per = 1e9 / static_cast<double>(steps * count);
    figures.push_back(figure("8. one Lyapunov vector, 1024 trajectories: host (1 thread) / hand-written tangent step",
                             "(report)", "ns per basic step per trajectory", t[0], t[1], per));
    figures.push_back(figure("8h. hand-written tangent step / hand-written plain step (the tangent map's own cost)",
                             "(report)", "ns per basic step per trajectory", t[1], t[2], per));
  }
  if (wanted("2")) {  // 2. 1024 trajectories, one thread
    const std::size_t count = 1024;
    // Long enough (about 0.5 s of host time) that the run's fixed costs (plugin load, H at start and end, three
    // fsyncs of about 10 ms each on this VM's disk) are a few percent: the figure is a cost per step.
    const auto steps = scaled(40000);
    const auto job = make_job(folder, "ensemble", analytic, count, steps);
    const double per = 1e9 / static_cast<double>(steps * count);
    std::vector<double> floor_q, native_q;
    const auto t = interleaved(
        repetitions, {[&] { return time_host(job, 1, host_q); }, [&] { return time_hand_written(job, reference_q); },
                      [&] { return time_abi_floor(job, minimal, false, floor_q); },
                      [&] { return time_core(job, core_q); }, [&] { return time_hand_written_native(job, native_q); }});
    check("figure 2", host_q, reference_q);
    if (native_q.size() != count) {
      std::fprintf(stderr, "figure 2: the two native hand-written loops disagree\n");
      agree = false;
    }
    check("figure 2a", floor_q, reference_q);
    check("figure 2c", core_q, reference_q);
    const char* unit = "ns per basic step per trajectory";
    const std::string n = native ? "n" : "";
    figures.push_back(figure("2" + n + ". 1024 trajectories: host (1 thread, kernel) / hand-written -march=native",
                             native ? "<= 1.10" : "<= 1.15", unit, t[0], t[4], per));
    figures.push_back(
        figure("2" + n + "p. 1024 trajectories: host (1 thread, kernel) / hand-written, this build's flags", "(report)",
               unit, t[0], t[1], per));
    figures.push_back(figure("2" + n + "a. 1024 trajectories: ABI floor (blocks of 256) / hand-written",
                             "(the floor of 2)", unit, t[2], t[1], per));
    figures.push_back(figure("2" + n + "h. 1024 trajectories: host / ABI floor (what the host adds)", "(report)", unit,
                             t[0], t[2], per));
    figures.push_back(figure("2" + n + "c. 1024 trajectories: ChinBasicStep on one batch / hand-written", "(report)",
                             unit, t[3], t[1], per));
  }
  if (wanted("3")) {  // 3. 2 threads over 1, 1024 trajectories: idle (3), a busy core (3b), hand-written (3c)
    const std::size_t count = 1024;
    const auto steps = scaled(200000);  // about 0.5 s on one thread: the run's fixed costs are serial (figure 2)
    const auto job = make_job(folder, "threads", analytic, count, steps);
    const double per = 1e9 / static_cast<double>(steps * count);
    std::vector<double> two_q;
    auto threads = [&](const char* what) {
      const auto [one, two] = interleaved(
          repetitions, [&] { return time_host(job, 1, host_q); }, [&] { return time_host(job, 2, two_q); });
      if (host_q != two_q) {
        std::fprintf(stderr, "%s: 2 threads give other final states than 1\n", what);
        agree = false;
      }
      return std::pair{one, two};
    };
    const auto [one, two] = threads("figure 3");
    figures.push_back(figure("3. 1024 trajectories: host 1 thread / 2 threads (speed-up)", ">= 1.85",
                             "ns per basic step per trajectory", one, two, per));
    {
      const BusyCore busy;
      if (!busy.running()) {
        std::fprintf(stderr, "figure 3b: could not start the busy process\n");
        agree = false;
      }
      const auto [busy_one, busy_two] = threads("figure 3b");
      figures.push_back(figure("3b. the same, another process spinning on one core", ">= 0.95",
                               "ns per basic step per trajectory", busy_one, busy_two, per));
    }
    std::vector<double> limit_two_q;
    const auto [limit_one, limit_two] = interleaved(
        repetitions, [&] { return time_hand_written_blocks(job, 1, reference_q); },
        [&] { return time_hand_written_blocks(job, 2, limit_two_q); });
    check("figure 3c (1 thread)", host_q, reference_q);
    check("figure 3c (2 threads)", host_q, limit_two_q);
    figures.push_back(figure("3c. 1024 trajectories, hand-written: 1 thread / 2 threads (the machine's speed-up)",
                             "(ceiling of 3)", "ns per basic step per trajectory", limit_one, limit_two, per));
  }
  if (wanted("4")) {  // 4. AD over analytic gradients, through the host
    const std::size_t count = 1024;
    // Long enough (about 0.5 s of host time) that the run's fixed costs (plugin load, H at start and end, three
    // fsyncs of about 10 ms each on this VM's disk) are a few percent: the figure is a cost per step.
    const auto steps = scaled(40000);
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
    figures.push_back(figure("4. 1024 trajectories: AD plugin / analytic plugin", "<= 2",
                             "ns per basic step per trajectory", ad, exact, 1e9 / static_cast<double>(steps * count)));
  }
  if (wanted("6b")) {  // 6b. output every 10^4 steps over no output, one trajectory
    const auto steps = scaled(4e6);
    const auto job_output = make_job(folder, "output", analytic, 1, steps, 10000);
    const auto job_silent = make_job(folder, "silent", analytic, 1, steps, 0);
    std::vector<double> silent_q;
    const auto [output, silent] = interleaved(
        repetitions, [&] { return time_host(job_output, 1, host_q); },
        [&] { return time_host(job_silent, 1, silent_q); });
    if (host_q != silent_q) {
      std::fprintf(stderr, "figure 6b: output changes the final state\n");
      agree = false;
    }
    figures.push_back(figure("6b. one trajectory: output every 10^4 steps / no output", "~ 1", "ns per basic step",
                             output, silent, 1e9 / static_cast<double>(steps)));
  }
  if (wanted("6c")) {  // 6c. H at every step (energy_every = 1) over H at start and end only
    const auto steps = scaled(4e6);
    const auto job_energy = make_job(folder, "energy", analytic, 1, steps, 0, 1);
    const auto job_silent = make_job(folder, "silent", analytic, 1, steps, 0, 0);
    std::vector<double> silent_q;
    const auto [energy, silent] = interleaved(
        repetitions, [&] { return time_host(job_energy, 1, host_q); },
        [&] { return time_host(job_silent, 1, silent_q); });
    if (host_q != silent_q) {
      std::fprintf(stderr, "figure 6c: evaluating H changes the final state\n");
      agree = false;
    }
    figures.push_back(figure("6c. one trajectory: H at every step / H at start and end", "(informative)",
                             "ns per basic step", energy, silent, 1e9 / static_cast<double>(steps)));
  }
  std::filesystem::remove_all(folder);

  double load[3] = {0, 0, 0};
  if (::getloadavg(load, 3) != 3) load[0] = load[1] = load[2] = -1;
  std::printf(
      "paper1d, basic step, dt = %g; median of %d interleaved repetitions%s; %u hardware threads; "
      "SIMD: %s; kernel: %s; load average at the end %.2f %.2f %.2f\n",
      dt, repetitions, smoke ? " (smoke run: short, not for the record)" : "", std::thread::hardware_concurrency(),
      simd, kernel.c_str(), load[0], load[1], load[2]);
  std::printf(
      "| figure | ratio | spread (min-max) | target | measured | reference | unit |\n"
      "|---|---|---|---|---|---|---|\n");
  for (const auto& f : figures)
    std::printf("| %s | %.3f | %.3f-%.3f | %s | %.4g | %.4g | %s |\n", f.name.c_str(), f.value, f.low, f.high,
                f.target.c_str(), f.measured, f.reference, f.unit.c_str());
  std::printf("final states: host = hand-written %s, 2 threads = 1 thread, AD ~ analytic: %s\n",
              all_exact ? "(bit for bit)" : "(within 1e-9, not bit for bit: FMA build or kernel)",
              agree ? "yes" : "NO");
  return agree ? 0 : 1;
}
