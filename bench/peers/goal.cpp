// The goal of issue 17, measured side by side in one run: at each phase-space accuracy 1e-4, 1e-6, 1e-8, 1e-10 on
// the two paper problems (paper1d to its quarter period, tao_product to t = 5; benchmark_problems.hpp), the time of
// the fastest *symplectic* scheme nonsep offers (Chin's basic and triplet, tao 2/4/6, implicit midpoint, gauss 4/6;
// every one through nonsep::Integrator, as the host runs it) against the fastest of GSL's symplectic methods
// (rk2imp, rk4imp at driver tolerances 1e-5 .. 1e-14, gsl_gauss_methods.hpp):
//   single:   one trajectory each; ratio = GSL time / nonsep time (> 1: nonsep is faster);
//   ensemble: 1024 trajectories, nonsep as one batch per thread (std::thread::hardware_concurrency() threads, each
//             its own Integrator over 1024/threads states), per-trajectory time = wall time / 1024, against GSL's
//             single-trajectory time (GSL steps one trajectory at a time; run on the same threads it would be at
//             most `threads` times faster, which the table states next to the ratio).
// "Cheapest" is the smallest time among the settings (step count; tolerance for GSL) whose phase error meets the
// target. Ensemble runs start every state at the problem's initial point (same accuracy as the single run) and
// are timed for the three fastest single-trajectory settings of each target. Times: median of 5 batches, each
// batch repeating the run for at least 5 ms (ensembles: median of 5 runs). The machine is shared: timings vary.
//
// Usage: nonsep_bench_goal [--out FILE.csv] [--smoke]   (--smoke: targets 1e-4 only, short ladders)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "benchmark_problems.hpp"
#include "nonsep/core/integrator.hpp"
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

struct Point {
  std::string method, setting;
  std::size_t steps = 0;
  double tolerance = 0.0;  // GSL only
  IntegratorSpec spec;     // nonsep only
  double error = 0.0, seconds = 0.0;
};

volatile double sink = 0.0;

double median_seconds(const std::function<double()>& run) {
  using clock = std::chrono::steady_clock;
  auto start = clock::now();
  sink = sink + run();
  const double first = std::chrono::duration<double>(clock::now() - start).count();
  const auto per_batch = static_cast<std::size_t>(std::clamp(std::ceil(5e-3 / std::max(first, 1e-9)), 1.0, 1e6));
  std::vector<double> samples;
  for (int r = 0; r < 5; ++r) {
    start = clock::now();
    for (std::size_t i = 0; i < per_batch; ++i) sink = sink + run();
    samples.push_back(std::chrono::duration<double>(clock::now() - start).count() / static_cast<double>(per_batch));
  }
  std::sort(samples.begin(), samples.end());
  return samples[2];
}

std::string label(const IntegratorSpec& spec) {
  if (spec.scheme == "gauss") return "gauss " + std::to_string(2 * static_cast<int>(spec.stages));
  if (spec.scheme == "basic" || spec.scheme == "implicit_midpoint") return spec.scheme;
  return spec.scheme + " " + spec.order.to_string();
}

std::vector<IntegratorSpec> symplectic_schemes() {
  std::vector<IntegratorSpec> specs{{"basic", Fraction(2, 3)},   {"triplet", Fraction(4, 3)}, {"triplet", Fraction(2)},
                                    {"triplet", Fraction(8, 3)}, {"tao", Fraction(2)},        {"tao", Fraction(4)},
                                    {"tao", Fraction(6)},        {"implicit_midpoint"}};
  for (const int stages : {2, 3}) {
    IntegratorSpec gauss{"gauss"};
    gauss.stages = stages;
    specs.push_back(gauss);
  }
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
    if (point.error < floor_error || point.seconds > 0.1 || (best < 1e-3 && stalled >= 4)) break;
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
          Point point{label(spec), "steps=" + std::to_string(steps), steps, 0.0, spec};
          point.error = run_nonsep<P>(s, spec, steps, 1);
          point.seconds = median_seconds([&] { return run_nonsep<P>(s, spec, steps, 1); });
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
            Point point{name, setting, steps, tolerance, {}};
            point.error = r.succeeded ? std::hypot(r.q - s.q_end, r.p - s.p_end) : std::nan("");
            point.seconds = median_seconds([&] { return gsl.run(s.q0, s.p0, s.t_end, steps).q; });
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
    std::sort(meeting.begin(), meeting.end(), [](const Point& a, const Point& b) { return a.seconds < b.seconds; });
    const Point* gsl = nullptr;
    for (const Point& p : gsl_points)
      if (p.error <= target && (!gsl || p.seconds < gsl->seconds)) gsl = &p;
    // The ensemble: the three fastest single-trajectory settings, each 1024 states over `threads` threads.
    double ensemble_best = std::numeric_limits<double>::infinity();
    std::string ensemble_method;
    for (std::size_t k = 0; k < std::min<std::size_t>(3, meeting.size()); ++k) {
      std::vector<double> samples;
      for (int r = 0; r < 5; ++r) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<std::thread> pool;
        for (unsigned t = 0; t < threads; ++t)
          pool.emplace_back([&, t] {
            const std::size_t share = ensemble / threads + (t < ensemble % threads ? 1 : 0);
            sink = sink + run_nonsep<P>(s, meeting[k].spec, meeting[k].steps, share);
          });
        for (auto& thread : pool) thread.join();
        samples.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      std::sort(samples.begin(), samples.end());
      const double per_trajectory = samples[2] / ensemble;
      if (per_trajectory < ensemble_best) {
        ensemble_best = per_trajectory;
        ensemble_method = meeting[k].method + " " + meeting[k].setting;
      }
    }
    const bool have = !meeting.empty();
    std::printf("| %s | %.0e | %s | %s | %s | %s | %s | %s | %s |\n", s.name, target,
                have ? (meeting[0].method + " " + meeting[0].setting).c_str() : "not reached",
                have ? std::to_string(meeting[0].seconds).c_str() : "-",
                gsl ? (gsl->method + " " + gsl->setting).c_str() : "not reached",
                gsl ? std::to_string(gsl->seconds).c_str() : "-",
                have && gsl ? std::to_string(gsl->seconds / meeting[0].seconds).c_str() : "-",
                have ? (ensemble_method + ": " + std::to_string(ensemble_best)).c_str() : "-",
                have && gsl ? std::to_string(gsl->seconds / ensemble_best).c_str() : "-");
    csv << s.name << ',' << target << ',' << (have ? meeting[0].method + " " + meeting[0].setting : "") << ','
        << (have ? meeting[0].seconds : std::nan("")) << ',' << (gsl ? gsl->method + " " + gsl->setting : "") << ','
        << (gsl ? gsl->seconds : std::nan("")) << ',' << ensemble_method << ',' << ensemble_best << ',' << threads
        << '\n';
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
  csv << "problem,target,nonsep_single,nonsep_single_seconds,gsl_single,gsl_single_seconds,nonsep_ensemble,"
         "nonsep_ensemble_seconds_per_trajectory,threads\n";
  std::printf("threads for the ensemble: %u\n", std::max(1u, std::thread::hardware_concurrency()));
  std::printf(
      "| problem | target | fastest nonsep (1 trajectory) | s | fastest GSL symplectic | s | ratio GSL/nonsep "
      "| nonsep 1024-ensemble: s per trajectory | ratio GSL/nonsep per trajectory "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  measure<Paper1D>({"paper1d", 2.0, 0.0, quarter.period, 0.0, quarter.p_final}, targets, smoke, csv);
  // tao_product's end point: RKF78 at tolerance 1e-14 (docs/performance-peers.md), good to about 5e-12.
  measure<TaoProduct>({"tao_product", -3.0, 0.0, 5.0, 2.831292408550297, -0.3303220398135333}, targets, smoke, csv);
  return csv ? 0 : 1;
}
