// The goal of docs/work-precision.md, measured side by side in one run: at each phase-space accuracy 1e-4, 1e-6, 1e-8,
// 1e-10 on the two paper problems (paper1d to its quarter period, tao_product to t = 5; benchmark_problems.hpp), the
// time of the fastest *symplectic* scheme nonsep offers (Chin's basic and triplet, tao 2/4/6, implicit midpoint, gauss
// 4/6; every one through nonsep::Integrator, as the host runs it) against the fastest of GSL's symplectic methods
// (rk2imp, rk4imp at driver tolerances 1e-5 .. 1e-14, gsl_gauss_methods.hpp):
//   single:   one trajectory each; ratio = GSL time / nonsep time (> 1: nonsep is faster);
//   ensemble: 1024 trajectories, nonsep as one batch per thread (std::thread::hardware_concurrency() threads, each
//             its own Integrator over 1024/threads states), per-trajectory time = time / 1024, against GSL's
//             single-trajectory time (GSL steps one trajectory at a time; run on the same threads it would be at
//             most `threads` times faster).
// Every time is given twice: CPU time (of the timing thread; for an ensemble that of its busiest thread), which is
// the wall time on idle cores and barely moves with the load of the shared machine, and wall time. "Fastest" is
// the smallest CPU time among the settings (step count; tolerance for GSL) whose phase error meets the target.
// Ensemble runs start every state at the problem's initial point (same accuracy as the single run) and are timed
// for the three fastest single-trajectory settings of each target. Times: medians of 5 batches, each batch
// repeating the run for at least 5 ms (ensembles: medians of 5 runs).
//
// Usage: nonsep_bench_goal [--out FILE.csv] [--smoke]   (--smoke: targets 1e-4 only, short ladders)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "benchmark_problems.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#ifdef NONSEP_BENCH_HAVE_GSL
#include "gsl_gauss_methods.hpp"
#endif

using namespace nonsep;
using namespace nonsep::bench;

namespace {

struct Setup {
  const char* name;
  double q0, p0, t_end, q_end, p_end;
};

struct Timing {
  double wall = 0.0, cpu = 0.0;  // seconds
};

struct Point {
  std::string method, setting;
  std::size_t steps = 0;
  double tolerance = 0.0;  // GSL only
  IntegratorSpec spec;     // nonsep only
  double error = 0.0;
  Timing time;
};

volatile double sink = 0.0;

// CPU time of the calling thread: what a run costs whatever else the shared machine is doing.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Medians over 5 batches of the wall and CPU time of one run, each batch repeating it for at least 5 ms.
Timing median_time(const std::function<double()>& run) {
  using clock = std::chrono::steady_clock;
  auto start = clock::now();
  sink = sink + run();
  const double first = std::chrono::duration<double>(clock::now() - start).count();
  const auto per_batch = static_cast<std::size_t>(std::clamp(std::ceil(5e-3 / std::max(first, 1e-9)), 1.0, 1e6));
  std::vector<double> wall, cpu;
  for (int r = 0; r < 5; ++r) {
    start = clock::now();
    const double cpu_start = thread_cpu_seconds();
    for (std::size_t i = 0; i < per_batch; ++i) sink = sink + run();
    cpu.push_back((thread_cpu_seconds() - cpu_start) / static_cast<double>(per_batch));
    wall.push_back(std::chrono::duration<double>(clock::now() - start).count() / static_cast<double>(per_batch));
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  return {wall[2], cpu[2]};
}

std::string label(const IntegratorSpec& spec) {
  if (spec.scheme == "basic" || spec.scheme == "implicit_midpoint") return spec.scheme;
  return spec.scheme + " " + Integrator::describe(spec).order.to_string();
}

std::vector<IntegratorSpec> symplectic_schemes() {
  std::vector<IntegratorSpec> specs{{"basic", ChinOptions{Fraction(2, 3)}}, {"triplet", ChinOptions{Fraction(4, 3)}},
                                    {"triplet", ChinOptions{Fraction(2)}},  {"triplet", ChinOptions{Fraction(8, 3)}},
                                    {"tao", TaoOptions{Fraction(2)}},       {"tao", TaoOptions{Fraction(4)}},
                                    {"tao", TaoOptions{Fraction(6)}},       {"implicit_midpoint"}};
  for (const int stages : {2, 3}) specs.push_back({"gauss", GaussOptions{stages}});
  return specs;
}

// Steps a batch of `count` copies of the initial state; returns the phase error of state 0 (all are equal).
template <class P>
double run_nonsep(const Setup& s, const IntegratorSpec& spec, std::size_t steps, std::size_t count) {
  const BatchedModel<P> model;
  Integrator integrator(spec);
  PhaseSpaceBatch x(1, count);
  std::fill(x.q().begin(), x.q().end(), s.q0);
  std::fill(x.p().begin(), x.p().end(), s.p0);
  const double dt = s.t_end / static_cast<double>(steps);
  for (std::size_t i = 0; i < steps; ++i) integrator.step(model, x, dt);
  return std::hypot(x.q()[0] - s.q_end, x.p()[0] - s.p_end);
}

// Step counts 2, 3, 4, 6, 8, ... (ratio sqrt 2) until the error is below 1e-11, a run takes over 0.1 s, the
// scheme fails, or the error stops improving.
void ladder(const std::function<Point(std::size_t)>& at, double floor_error, std::size_t max_steps,
            std::vector<Point>& points) {
  std::size_t previous = 0;
  double best = std::numeric_limits<double>::infinity();
  int stalled = 0;
  for (double n = 2; n <= static_cast<double>(max_steps); n *= std::sqrt(2.0)) {
    const auto steps = static_cast<std::size_t>(std::llround(n));
    if (steps == previous) continue;
    previous = steps;
    Point point;
    try {
      point = at(steps);
    } catch (const std::exception&) {  // a Gauss iteration that does not contract at this dt
      continue;
    }
    if (!std::isfinite(point.error)) continue;
    points.push_back(point);
    stalled = point.error < best / 2 ? 0 : stalled + 1;
    best = std::min(best, point.error);
    if (point.error < floor_error || point.time.wall > 0.1 || (best < 1e-3 && stalled >= 4)) break;
  }
}

template <class P>
void measure(const Setup& s, const std::vector<double>& targets, bool smoke, std::ofstream& csv) {
  std::vector<Point> nonsep_points, gsl_points;
  const std::size_t max_steps = smoke ? 512 : (1u << 22);
  const double floor_error = smoke ? 1e-5 : 1e-11;
  for (const IntegratorSpec& spec : symplectic_schemes())
    ladder(
        [&](std::size_t steps) {
          Point point{label(spec), "steps=" + std::to_string(steps), steps, 0.0, spec, 0.0, {}};
          point.error = run_nonsep<P>(s, spec, steps, 1);
          point.time = median_time([&] { return run_nonsep<P>(s, spec, steps, 1); });
          return point;
        },
        floor_error, max_steps, nonsep_points);
#ifdef NONSEP_BENCH_HAVE_GSL
  gsl_set_error_handler_off();
  const std::pair<const char*, const gsl_odeiv2_step_type*> methods[] = {{"gsl rk2imp", gsl_odeiv2_step_rk2imp},
                                                                         {"gsl rk4imp", gsl_odeiv2_step_rk4imp}};
  for (const auto& [name, type] : methods)
    for (const double tolerance : {1e-5, 1e-8, 1e-11, 1e-14}) {
      GslFixedStep<P> gsl(type, tolerance);
      ladder(
          [&](std::size_t steps) {
            const RunResult r = gsl.run(s.q0, s.p0, s.t_end, steps);
            char setting[64];
            std::snprintf(setting, sizeof setting, "steps=%zu tol=%g", steps, tolerance);
            Point point{name, setting, steps, tolerance, {}, 0.0, {}};
            point.error = r.succeeded ? std::hypot(r.q - s.q_end, r.p - s.p_end) : std::nan("");
            point.time = median_time([&] { return gsl.run(s.q0, s.p0, s.t_end, steps).q; });
            return point;
          },
          floor_error, max_steps, gsl_points);
    }
#endif
  const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t ensemble = 1024;
  for (const double target : targets) {
    std::vector<Point> meeting;
    for (const Point& p : nonsep_points)
      if (p.error <= target) meeting.push_back(p);
    std::sort(meeting.begin(), meeting.end(), [](const Point& a, const Point& b) { return a.time.cpu < b.time.cpu; });
    const Point* gsl = nullptr;
    for (const Point& p : gsl_points)
      if (p.error <= target && (!gsl || p.time.cpu < gsl->time.cpu)) gsl = &p;
    // The ensemble: the three fastest single-trajectory settings, each 1024 states over `threads` threads. Its CPU
    // time is that of the busiest thread (the wall time on `threads` idle cores).
    Timing ensemble_best{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    std::string ensemble_method;
    for (std::size_t k = 0; k < std::min<std::size_t>(3, meeting.size()); ++k) {
      std::vector<double> wall, cpu;
      for (int r = 0; r < 5; ++r) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<double> thread_cpu(threads);
        std::vector<std::thread> pool;
        for (unsigned t = 0; t < threads; ++t)
          pool.emplace_back([&, t] {
            const double cpu_start = thread_cpu_seconds();
            const std::size_t share = ensemble / threads + (t < ensemble % threads ? 1 : 0);
            sink = sink + run_nonsep<P>(s, meeting[k].spec, meeting[k].steps, share);
            thread_cpu[t] = thread_cpu_seconds() - cpu_start;
          });
        for (auto& thread : pool) thread.join();
        wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / ensemble);
        cpu.push_back(*std::max_element(thread_cpu.begin(), thread_cpu.end()) / ensemble);
      }
      std::sort(wall.begin(), wall.end());
      std::sort(cpu.begin(), cpu.end());
      if (cpu[2] < ensemble_best.cpu) {
        ensemble_best = {wall[2], cpu[2]};
        ensemble_method = meeting[k].method + " " + meeting[k].setting;
      }
    }
    const bool have = !meeting.empty();
    auto us = [](double seconds) {
      char text[32];
      std::snprintf(text, sizeof text, "%.1f", seconds * 1e6);
      return std::string(text);
    };
    auto ratio = [](double a, double b) {
      char text[32];
      std::snprintf(text, sizeof text, "%.2f", a / b);
      return std::string(text);
    };
    std::printf(
        "| %s | %.0e | %s | %s | %s | %s | %s | %s | %s | %s |\n", s.name, target,
        have ? (meeting[0].method + " " + meeting[0].setting).c_str() : "not reached",
        have ? (us(meeting[0].time.cpu) + " (" + us(meeting[0].time.wall) + ")").c_str() : "-",
        gsl ? (gsl->method + " " + gsl->setting).c_str() : "not reached",
        gsl ? (us(gsl->time.cpu) + " (" + us(gsl->time.wall) + ")").c_str() : "-",
        have && gsl
            ? (ratio(gsl->time.cpu, meeting[0].time.cpu) + " (" + ratio(gsl->time.wall, meeting[0].time.wall) + ")")
                  .c_str()
            : "-",
        have ? ensemble_method.c_str() : "-",
        have ? (us(ensemble_best.cpu) + " (" + us(ensemble_best.wall) + ")").c_str() : "-",
        have && gsl
            ? (ratio(gsl->time.cpu, ensemble_best.cpu) + " (" + ratio(gsl->time.wall, ensemble_best.wall) + ")").c_str()
            : "-");
    const double nan = std::nan("");
    csv << s.name << ',' << target << ',' << (have ? meeting[0].method + " " + meeting[0].setting : "") << ','
        << (have ? meeting[0].time.cpu : nan) << ',' << (have ? meeting[0].time.wall : nan) << ','
        << (gsl ? gsl->method + " " + gsl->setting : "") << ',' << (gsl ? gsl->time.cpu : nan) << ','
        << (gsl ? gsl->time.wall : nan) << ',' << ensemble_method << ',' << ensemble_best.cpu << ','
        << ensemble_best.wall << ',' << threads << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  std::string out = "goal.csv";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke") {
      smoke = true;
    } else if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else {
      std::fprintf(stderr, "usage: nonsep_bench_goal [--out FILE.csv] [--smoke]\n");
      return 2;
    }
  }
  for (const auto& failures : {check_derivatives<Paper1D>(), check_derivatives<TaoProduct>()})
    if (!failures.empty()) {
      std::fprintf(stderr, "derivative check failed: %s\n", failures.front().c_str());
      return 1;
    }
#ifndef NONSEP_BENCH_HAVE_GSL
  std::printf("note: built without GSL: no peer times\n");
#endif
  const auto quarter = reference::paper1d_quarter(2.0);
  const std::vector<double> targets = smoke ? std::vector<double>{1e-4} : std::vector<double>{1e-4, 1e-6, 1e-8, 1e-10};
  std::ofstream csv(out);
  csv << "problem,target,nonsep_single,nonsep_single_cpu_seconds,nonsep_single_wall_seconds,gsl_single,"
         "gsl_single_cpu_seconds,gsl_single_wall_seconds,nonsep_ensemble,nonsep_ensemble_cpu_seconds_per_trajectory,"
         "nonsep_ensemble_wall_seconds_per_trajectory,threads\n";
  std::printf("threads for the ensemble: %u\n", std::max(1u, std::thread::hardware_concurrency()));
  std::printf(
      "times in microseconds, CPU (wall)\n| problem | target | fastest nonsep (1 trajectory) | µs | fastest GSL "
      "symplectic | µs | GSL / nonsep | nonsep 1024-ensemble | µs per trajectory | GSL / nonsep per trajectory "
      "|\n|---|---|---|---|---|---|---|---|---|---|\n");
  measure<Paper1D>({"paper1d", 2.0, 0.0, quarter.period, 0.0, quarter.p_final}, targets, smoke, csv);
  // tao_product's end point: RKF78 at tolerance 1e-14 (docs/performance-peers.md), good to about 5e-12.
  measure<TaoProduct>({"tao_product", -3.0, 0.0, 5.0, 2.831292408550297, -0.3303220398135333}, targets, smoke, csv);
  return csv ? 0 : 1;
}
