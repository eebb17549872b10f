// Energy over 10^5 periods at equal accuracy (docs/performance-peers.md, "Energy drift at equal accuracy"): each
// method set as a user sets it for a target, then run long.
//
// The setting: on the ensemble of docs/performance-peers.md's ensemble table (paper1d, q0 = 0.2 + 1.8 j / 1024,
// p0 = 0), every 16th orbit and the last (j = 0, 16, ..., 1008, 1023: 65 orbits), the largest phase-space distance at
// t = 10 from a reference (Odeint's runge_kutta_fehlberg78 at tolerance 1e-15, as there) must be at most the target
// (1e-8 and 1e-10 by default). Each method takes the cheapest setting of its ladder that meets it:
//   nonsep gauss 16 (8 stages, `auto`'s choice on this ensemble) and gauss 6 (3 stages), fixed steps through
//     nonsep::Integrator (as the host steps them): N steps over t = 10, N = 8, 9, 10, ... (about 3% apart);
//   Odeint's runge_kutta_dopri5 and runge_kutta_fehlberg78 under make_controlled, and bulirsch_stoer, with absolute
//     and relative tolerance 10^(-k/2) from 1e-5 to 1e-15, driven by integrate_adaptive from dt = 1e-3 (as
//     nonsep_bench_ensemble_peer drives them).
// The long run: the ensemble's last orbit (q0 = 0.2 + 1.8 * 1023/1024, the largest amplitude, period 4 x the exact
// quarter period of nonsep::reference::paper1d_quarter) over P periods (default 10^5), one continuous run per method
// at its setting (Odeint's controller keeps its step from one step to the next; its observer sees every accepted
// step). After every step the relative energy error |H - E0| / E0, H in closed form; its maximum over blocks of
// periods log-spaced at 10 per decade.
//
// Output: drift_at_equal_accuracy.csv (target, method, family, setting, calls_per_period, ensemble_error,
// block_first_period, block_last_period, max_relative_energy_error; calls are evaluations of Hamilton's equations or
// gradients of H), and a table on stdout: the setting, its ensemble error, the envelope over periods 1-10 and over the
// last decade, the slope of log(envelope) against log(period) over the last two decades (about 0: bounded; 1:
// linear drift) and the long run's seconds. Methods run in parallel on the available threads, each single-threaded.
//
// Exit status 1 when a method has no setting in its ladder that meets a target, or its long run's energy error is not
// finite; 2 for a bad argument (named).
//
// Usage: nonsep_bench_drift_at_equal_accuracy [--out FILE.csv] [--periods P] [--target E]...   (--periods 30: smoke)
#include <algorithm>
#include <atomic>
#include <boost/numeric/odeint.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "benchmark_problems.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "odeint_methods.hpp"
#include "period_blocks.hpp"

using namespace nonsep;
using namespace nonsep::bench;

namespace {

constexpr double t_check = 10.0;

double energy(const OdeintState& x) { return Paper1D::H(x[0], x[1]); }

std::vector<OdeintState> ensemble() {
  std::vector<OdeintState> states;
  for (int j = 0; j < 1024; j += 16) states.push_back({0.2 + 1.8 * j / 1024.0, 0.0});
  states.push_back({0.2 + 1.8 * 1023 / 1024.0, 0.0});
  return states;
}

// Sees a run's states after every step: the largest relative energy error per block of periods.
class Envelope {
 public:
  Envelope(double energy, double period, std::size_t periods)
      : energy_(energy), period_(period), blocks_(period_blocks(periods)) {}
  void see(const OdeintState& x, double t) {
    const auto period = static_cast<std::size_t>(t / period_);
    while (b_ < blocks_.size() && blocks_[b_].last <= period) ++b_;
    if (b_ == blocks_.size()) return;  // the last step may end a hair past the last period
    const double error = std::abs(energy(x) - energy_) / energy_;
    blocks_[b_].max_error = std::isfinite(error) ? std::max(blocks_[b_].max_error, error) : INFINITY;
  }
  const std::vector<PeriodBlock>& blocks() const { return blocks_; }

 private:
  double energy_, period_;
  std::vector<PeriodBlock> blocks_;
  std::size_t b_ = 0;
};

// A method at one setting: runs a state from 0 to t_end, showing every step to `see` (may be empty); returns the
// calls (evaluations of Hamilton's equations, or gradients of H) it took.
using Runner = std::function<std::uint64_t(OdeintState&, double t_end,
                                           const std::function<void(const OdeintState&, double)>& see)>;

struct Method {
  std::string name, family;
  std::vector<std::string> settings;      // the ladder, loosest (cheapest) first
  std::function<Runner(std::size_t)> at;  // the runner at setting i
};

Runner gauss_runner(int stages, std::size_t steps_per_check) {
  return [stages, steps_per_check](OdeintState& x, double t_end, const auto& see) -> std::uint64_t {
    Integrator integrator(IntegratorSpec{"gauss", GaussOptions{stages}});
    PhaseSpaceBatch batch(1, 1);
    batch.q()[0] = x[0], batch.p()[0] = x[1];
    const double dt = t_check / static_cast<double>(steps_per_check);
    const auto steps = static_cast<std::size_t>(std::llround(t_end / dt));
    for (std::size_t k = 1; k <= steps; ++k) {
      integrator.step(BatchedModel<Paper1D>{}, batch, dt);
      if (see) see({batch.q()[0], batch.p()[0]}, static_cast<double>(k) * dt);
    }
    x = {batch.q()[0], batch.p()[0]};
    return integrator.evaluations().grad_H;
  };
}

// GCC warns that Odeint's controlled_runge_kutta copies the fehlberg78 stepper's scratch arrays before they are
// written (std::array members, default-initialised); they are written before they are read.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
Runner odeint_runner(const std::string& method, double tolerance) {
  namespace odeint = boost::numeric::odeint;
  return [method, tolerance](OdeintState& x, double t_end, const auto& see) -> std::uint64_t {
    std::uint64_t calls = 0;
    const CountedHamiltonEquations<Paper1D> system{&calls};
    const auto observe = [&see](const OdeintState& state, double t) {
      if (see && t > 0.0) see(state, t);
    };
    const double dt = 1e-3;
    if (method == "dopri5")
      odeint::integrate_adaptive(
          odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<OdeintState>()), system, x, 0.0,
          t_end, dt, observe);
    else if (method == "fehlberg78")
      odeint::integrate_adaptive(
          odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<OdeintState>()), system, x, 0.0,
          t_end, dt, observe);
    else
      odeint::integrate_adaptive(odeint::bulirsch_stoer<OdeintState>(tolerance, tolerance), system, x, 0.0, t_end, dt,
                                 observe);
    return calls;
  };
}
#pragma GCC diagnostic pop

std::vector<Method> methods() {
  std::vector<Method> list;
  for (const int stages : {8, 3}) {
    Method m{"nonsep gauss " + std::to_string(2 * stages), "nonsep", {}, {}};
    std::vector<std::size_t> ladder;
    for (double n = 8; n <= 20000; n = std::max(n + 1, std::round(n * 1.03)))
      ladder.push_back(static_cast<std::size_t>(n));
    for (const std::size_t n : ladder) m.settings.push_back(std::to_string(n) + " steps to t = 10");
    m.at = [stages, ladder](std::size_t i) { return gauss_runner(stages, ladder[i]); };
    list.push_back(m);
  }
  for (const std::string method : {"dopri5", "fehlberg78", "bulirsch_stoer"}) {
    Method m{"odeint " + method, "odeint", {}, {}};
    std::vector<double> ladder;
    for (int k = 10; k <= 30; ++k) ladder.push_back(std::pow(10.0, -k / 2.0));
    for (const double tolerance : ladder) {
      char text[32];
      std::snprintf(text, sizeof text, "tol=%.3g", tolerance);
      m.settings.push_back(text);
    }
    m.at = [method, ladder](std::size_t i) { return odeint_runner(method, ladder[i]); };
    list.push_back(m);
  }
  return list;
}

double largest_error(const Runner& run, const std::vector<OdeintState>& start, const std::vector<OdeintState>& truth,
                     std::uint64_t* calls) {
  double worst = 0.0;
  *calls = 0;
  for (std::size_t i = 0; i < start.size(); ++i) {
    OdeintState x = start[i];
    try {
      *calls += run(x, t_check, {});
    } catch (const std::exception&) {  // a Gauss iteration that does not contract at a coarse step
      return INFINITY;
    }
    const double d = std::hypot(x[0] - truth[i][0], x[1] - truth[i][1]);
    worst = std::isfinite(d) ? std::max(worst, d) : INFINITY;
  }
  return worst;
}

struct Result {
  std::string method, family, setting = "none in the ladder";
  double ensemble_error = NAN, calls_per_period = NAN, seconds = NAN;
  std::vector<PeriodBlock> envelope;
};

}  // namespace

int main(int argc, char** argv) {
  std::string out = "drift_at_equal_accuracy.csv";
  std::size_t periods = 100000;
  std::vector<double> targets;
  const auto usage = [](const std::string& problem) {
    std::fprintf(stderr,
                 "nonsep_bench_drift_at_equal_accuracy: %s\nusage: nonsep_bench_drift_at_equal_accuracy [--out "
                 "FILE.csv] [--periods P >= 1] [--target E > 0]...\n",
                 problem.c_str());
    return 2;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::string value = i + 1 < argc ? argv[i + 1] : "";
    std::size_t used = 0;
    try {
      if (arg == "--out" && i + 1 < argc) {
        out = value;
      } else if (arg == "--periods" && i + 1 < argc) {
        const long long p = std::stoll(value, &used);
        if (used != value.size() || p < 1) return usage("--periods " + value + ": a whole number >= 1 needed");
        periods = static_cast<std::size_t>(p);
      } else if (arg == "--target" && i + 1 < argc) {
        const double e = std::stod(value, &used);
        if (used != value.size() || !std::isfinite(e) || !(e > 0.0))
          return usage("--target " + value + ": a finite number > 0 needed");
        targets.push_back(e);
      } else {
        return usage("unknown or incomplete argument " + arg);
      }
    } catch (const std::exception&) {  // std::stoll, std::stod: not a number, or out of range
      return usage(arg + " " + value + ": not a number");
    }
    ++i;
  }
  if (targets.empty()) targets = {1e-8, 1e-10};
  std::ofstream csv(out);  // opened before the runs: a path that cannot be written fails at once
  if (!csv) return usage("--out " + out + ": cannot be written");
  if (const auto failures = check_derivatives<Paper1D>(); !failures.empty()) {
    std::fprintf(stderr, "%s\n", failures.front().c_str());
    return 1;
  }

  const std::vector<OdeintState> start = ensemble();
  std::vector<OdeintState> truth = start;
  for (OdeintState& x : truth) odeint_runner("fehlberg78", 1e-15)(x, t_check, {});
  const OdeintState orbit = start.back();
  const double period = 4.0 * reference::paper1d_quarter(orbit[0]).period, e0 = energy(orbit);

  const std::vector<Method> list = methods();
  struct Job {
    double target;
    std::size_t method;
  };
  std::vector<Job> jobs;
  for (const double target : targets)
    for (std::size_t m = 0; m < list.size(); ++m) jobs.push_back({target, m});
  std::vector<Result> results(jobs.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t j; (j = next++) < jobs.size();) {
      const Method& method = list[jobs[j].method];
      Result& r = results[j];
      r.method = method.name, r.family = method.family;
      for (std::size_t i = 0; i < method.settings.size(); ++i) {
        std::uint64_t calls = 0;
        const double error = largest_error(method.at(i), start, truth, &calls);
        if (!(error <= jobs[j].target)) continue;
        r.setting = method.settings[i], r.ensemble_error = error;
        Envelope envelope(e0, period, periods);
        OdeintState x = orbit;
        const auto begin = std::chrono::steady_clock::now();
        const std::uint64_t long_calls = method.at(i)(x, static_cast<double>(periods) * period,
                                                      [&](const OdeintState& s, double t) { envelope.see(s, t); });
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
        r.calls_per_period = static_cast<double>(long_calls) / static_cast<double>(periods);
        r.envelope = envelope.blocks();
        break;
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < std::max(1u, std::thread::hardware_concurrency()); ++t) pool.emplace_back(worker);
  for (auto& thread : pool) thread.join();

  csv.precision(6);
  csv << "target,method,family,setting,calls_per_period,ensemble_error,block_first_period,block_last_period,"
         "max_relative_energy_error\n";
  std::printf(
      "paper1d from (%.17g, 0), period %.13g, %zu periods; the setting meets the target on 65 orbits at t = 10\n",
      orbit[0], period, periods);
  std::printf(
      "| target | method | setting | ensemble error | calls/period | max dE/E, periods 1-10 | max dE/E, last decade | "
      "slope, last 2 decades | s |\n|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const Result& r = results[j];
    if (r.envelope.empty()) {
      std::printf("| %.0e | %s | %s | - | - | - | - | - | - |\n", jobs[j].target, r.method.c_str(), r.setting.c_str());
      continue;
    }
    double early = 0.0, late = 0.0;
    for (const auto& b : r.envelope) {
      if (b.first < 10) early = std::max(early, b.max_error);
      if (b.first * 10 >= periods) late = std::max(late, b.max_error);
      csv << jobs[j].target << ',' << r.method << ',' << r.family << ',' << r.setting << ',' << r.calls_per_period
          << ',' << r.ensemble_error << ',' << b.first << ',' << b.last << ',' << b.max_error << '\n';
    }
    std::printf("| %.0e | %s | %s | %.2e | %.0f | %.2e | %.2e | %.2f | %.2f |\n", jobs[j].target, r.method.c_str(),
                r.setting.c_str(), r.ensemble_error, r.calls_per_period, early, late,
                slope_of_last_two_decades(r.envelope, periods), r.seconds);
  }
  // A method without a setting that meets a target, or a long run whose energy was not finite, leaves the comparison
  // incomplete: exit status 1 (the smoke test relies on it).
  const bool complete = std::all_of(results.begin(), results.end(), [](const Result& r) {
    return !r.envelope.empty() &&
           std::all_of(r.envelope.begin(), r.envelope.end(), [](const auto& b) { return std::isfinite(b.max_error); });
  });
  if (!complete) std::fprintf(stderr, "some method met no target or lost its energy: see the table\n");
  if (!csv) std::fprintf(stderr, "nonsep_bench_drift_at_equal_accuracy: writing %s failed\n", out.c_str());
  return csv && complete ? 0 : 1;
}
