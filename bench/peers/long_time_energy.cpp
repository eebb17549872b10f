// Long-time behaviour at equal cost per period (docs/work-precision.md): the relative energy error |H - E0| / E0 of
// paper1d from (q, p) = (2, 0) over 10^5 periods (period 4 x the exact quarter period of
// nonsep::reference::paper1d_quarter, 1.5455062293...), for Chin's basic and triplet (4/3, 2), Tao 2/4/6, implicit
// midpoint and Gauss 4/6 (each through nonsep::Integrator, as the host runs it), and as references GSL's rk4imp
// (2-stage Gauss by Newton) and Odeint's runge_kutta4 (explicit, not symplectic).
//
// Equal cost: every scheme spends the same number of model calls per period, a budget B (default 4096 and 16384):
//   grad T or grad V (Chin's kicks and drifts)              1 call each;
//   grad H (Tao, Gauss: hamiltonian_gradient.hpp)           4 calls: the gradient, two Hessians and the third
//                                                           derivative contraction it is built from;
//   the peers' Hamilton's equations f = (dH/dp, -dH/dq)     4 calls (it is grad H, simplified by hand), GSL's
//                                                           Jacobian also 4.
// A scheme's steps per period N are calibrated on 4 periods: N <- round(N B / calls per period), until the calls
// per period are within 2% of B (Gauss's iterations and GSL's Newton iterations per step fall as N grows, so the
// cost is measured, not assumed); the table gives the calls per period the long run really spent. GSL rk4imp takes
// the smallest driver tolerance (1e-14, 1e-12, ..., 1e-6: its Newton tolerance and local error bound) at which the
// calibration succeeds. A scheme that fails (a Gauss iteration that does not contract, GSL giving up, H not finite)
// is reported with the period it failed in.
//
// Output: the envelope max |dE/E| per block of periods, blocks log-spaced (10 per decade) from the first period to
// 10^5, in long_time_energy.csv, and a table on stdout: the envelope over periods 1-10 and over the last decade, and
// the slope of log(envelope) against log(period) over the last two decades (about 0: bounded; 1: linear drift).
// Energy H is evaluated in closed form after every step (not counted). Schemes run in parallel on the available
// threads; each is one single-threaded trajectory, so its numbers do not depend on the thread count.
//
// Usage: nonsep_bench_long_time [--out FILE.csv] [--periods N] [--budget B]...   (--periods 100: a smoke run)
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "benchmark_problems.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "odeint_methods.hpp"
#include "period_blocks.hpp"
#ifdef NONSEP_BENCH_HAVE_GSL
#include "gsl_gauss_methods.hpp"
#endif

using namespace nonsep;
using namespace nonsep::bench;

namespace {

constexpr double q0 = 2.0, p0 = 0.0;

// One trajectory of one scheme: step(dt) advances it (false when the scheme failed), calls() its model calls so far.
struct Trajectory {
  double q = q0, p = p0;
  std::function<bool(Trajectory&, double)> step;
  std::function<std::uint64_t()> calls;
};
using TrajectoryFactory = std::function<Trajectory()>;

struct Contender {
  std::string name, family;
  TrajectoryFactory make;
};

Trajectory nonsep_trajectory(const IntegratorSpec& spec) {
  auto integrator = std::make_shared<Integrator>(spec);
  auto x = std::make_shared<PhaseSpaceBatch>(1, 1);
  Trajectory t;
  t.step = [integrator, x](Trajectory& self, double dt) {
    x->q()[0] = self.q, x->p()[0] = self.p;
    try {
      integrator->step(BatchedModel<Paper1D>{}, *x, dt);
    } catch (const ModelError&) {  // a Gauss iteration that does not contract
      return false;
    }
    self.q = x->q()[0], self.p = x->p()[0];
    return true;
  };
  t.calls = [integrator] {
    const EvaluationCounts& e = integrator->evaluations();
    return e.grad_T + e.grad_V + 4 * e.grad_H;
  };
  return t;
}

Trajectory odeint_rk4_trajectory() {
  auto rhs = std::make_shared<std::uint64_t>(0);
  auto stepper = std::make_shared<boost::numeric::odeint::runge_kutta4<OdeintState>>();
  Trajectory t;
  t.step = [rhs, stepper](Trajectory& self, double dt) {
    OdeintState s{self.q, self.p};
    stepper->do_step(CountedHamiltonEquations<Paper1D>{rhs.get()}, s, 0.0, dt);
    self.q = s[0], self.p = s[1];
    return true;
  };
  t.calls = [rhs] { return 4 * *rhs; };
  return t;
}

#ifdef NONSEP_BENCH_HAVE_GSL
Trajectory gsl_trajectory(const gsl_odeiv2_step_type* method, double tolerance) {
  auto gsl = std::make_shared<GslFixedStep<Paper1D>>(method, tolerance);
  auto calls = std::make_shared<std::uint64_t>(0);
  Trajectory t;
  t.step = [gsl, calls](Trajectory& self, double dt) {
    const RunResult r = gsl->run(self.q, self.p, dt, 1);
    *calls += 4 * (r.evaluations + r.jacobian_evaluations);
    if (!r.succeeded) return false;
    self.q = r.q, self.p = r.p;
    return true;
  };
  t.calls = [calls] { return *calls; };
  return t;
}
#endif

std::vector<Contender> contenders() {
  std::vector<Contender> list;
  auto add = [&](const std::string& name, const std::string& family, IntegratorSpec spec) {
    list.push_back({name, family, [spec] { return nonsep_trajectory(spec); }});
  };
  add("basic", "chin", {"basic", ChinOptions{Fraction(2, 3)}});
  add("triplet 4/3", "chin", {"triplet", ChinOptions{Fraction(4, 3)}});
  add("triplet 2", "chin", {"triplet", ChinOptions{Fraction(2)}});
  for (const int order : {2, 4, 6}) add("tao " + std::to_string(order), "tao", {"tao", TaoOptions{Fraction(order)}});
  add("implicit midpoint", "gauss", {"implicit_midpoint"});
  for (const int stages : {2, 3}) {
    const IntegratorSpec spec{"gauss", GaussOptions{stages}};
    add("gauss " + std::to_string(2 * stages), "gauss", spec);
  }
  list.push_back({"odeint rk4", "peer", odeint_rk4_trajectory});
  return list;
}

struct Result {
  std::string name, family, note;
  std::size_t steps_per_period = 0;
  double calls_per_period = 0.0, seconds = 0.0;
  std::size_t failed_in_period = 0;  // 0: did not fail; else 1 + the period
  std::vector<PeriodBlock> envelope;
};

// Runs `periods` periods at N steps per period; returns the calls per period, or -1 when the scheme failed.
double run(const TrajectoryFactory& make, std::size_t n, std::size_t periods, double period,
           std::vector<PeriodBlock>* envelope = nullptr, std::size_t* failed_in = nullptr) {
  Trajectory t = make();
  const double dt = period / static_cast<double>(n), energy = Paper1D::H(q0, p0);
  std::size_t b = 0;
  for (std::size_t k = 0; k < periods; ++k) {
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double error = t.step(t, dt) ? std::abs(Paper1D::H(t.q, t.p) - energy) / energy : std::nan("");
      if (!std::isfinite(error)) {
        if (failed_in) *failed_in = k + 1;
        return -1.0;
      }
      worst = std::max(worst, error);
    }
    if (envelope) {
      while ((*envelope)[b].last <= k) ++b;
      (*envelope)[b].max_error = std::max((*envelope)[b].max_error, worst);
    }
  }
  return static_cast<double>(t.calls()) / static_cast<double>(periods);
}

// Steps per period at which one period costs about `budget` model calls, or 0 when the scheme fails there (fails at
// the step count the budget allows, having run at a finer one).
std::size_t calibrate(const TrajectoryFactory& make, double budget, double period) {
  std::size_t n = 64;
  bool ran = false;
  for (int round = 0; round < 16; ++round) {
    const double calls = run(make, n, 4, period);
    if (calls < 0.0) {
      if (ran) return 0;
      n *= 2;  // too coarse to start with
      if (static_cast<double>(n) > budget) return 0;
      continue;
    }
    ran = true;
    const auto next = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(n * budget / calls)));
    if (std::abs(calls - budget) <= 0.02 * budget || next == n) return n;
    n = next;
  }
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  std::string out = "long_time_energy.csv";
  std::size_t periods = 100000;
  std::vector<double> budgets;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--out" && i + 1 < argc) {
      out = argv[++i];
    } else if (arg == "--periods" && i + 1 < argc) {
      periods = std::stoul(argv[++i]);
    } else if (arg == "--budget" && i + 1 < argc) {
      budgets.push_back(std::stod(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: nonsep_bench_long_time [--out FILE.csv] [--periods N] [--budget B]...\n");
      return 2;
    }
  }
  if (budgets.empty()) budgets = {4096.0, 16384.0};
  const double period = 4.0 * reference::paper1d_quarter(q0).period;

  std::vector<Contender> list = contenders();
#ifdef NONSEP_BENCH_HAVE_GSL
  gsl_set_error_handler_off();
  list.push_back({"gsl rk4imp", "peer", {}});  // its tolerance is chosen per budget below
#else
  std::printf("note: built without GSL: no rk4imp\n");
#endif
  struct Job {
    double budget;
    std::size_t scheme;
  };
  std::vector<Job> jobs;
  for (const double budget : budgets)
    for (std::size_t s = 0; s < list.size(); ++s) jobs.push_back({budget, s});
  std::vector<Result> results(jobs.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t j; (j = next++) < jobs.size();) {
      const auto [budget, s] = jobs[j];
      Result& r = results[j];
      r.name = list[s].name, r.family = list[s].family;
      TrajectoryFactory make = list[s].make;
#ifdef NONSEP_BENCH_HAVE_GSL
      if (!make)
        for (const double tolerance : {1e-14, 1e-12, 1e-10, 1e-8, 1e-6}) {
          make = [tolerance] { return gsl_trajectory(gsl_odeiv2_step_rk4imp, tolerance); };
          char note[32];
          std::snprintf(note, sizeof note, "tol=%g", tolerance);
          r.note = note;
          if (calibrate(make, budget, period) > 0) break;
        }
#endif
      r.steps_per_period = calibrate(make, budget, period);
      if (r.steps_per_period == 0) continue;
      r.envelope = period_blocks(periods);
      const auto start = std::chrono::steady_clock::now();
      r.calls_per_period = run(make, r.steps_per_period, periods, period, &r.envelope, &r.failed_in_period);
      r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 0; t < std::max(1u, std::thread::hardware_concurrency()); ++t) pool.emplace_back(worker);
  for (auto& thread : pool) thread.join();

  std::ofstream csv(out);
  csv.precision(6);
  csv << "budget,scheme,family,note,steps_per_period,dt,calls_per_period,failed_in_period,block_first_period,"
         "block_last_period,max_relative_energy_error\n";
  std::printf(
      "paper1d from (2, 0), period %.13g, %zu periods; model calls per period: grad T, grad V 1; grad H, "
      "peer f, GSL Jacobian 4\n",
      period, periods);
  std::printf(
      "| budget | scheme | steps/period | calls/period | max dE/E, periods 1-10 | max dE/E, last decade "
      "| slope, last 2 decades | s |\n|---|---|---|---|---|---|---|---|\n");
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    const Result& r = results[j];
    const std::string label = r.name + (r.note.empty() ? "" : " (" + r.note + ")");
    if (r.steps_per_period == 0 || r.failed_in_period) {
      std::printf("| %.0f | %s | %zu | - | failed%s | - | - | - |\n", jobs[j].budget, label.c_str(), r.steps_per_period,
                  r.failed_in_period ? (" in period " + std::to_string(r.failed_in_period)).c_str()
                                     : " at every step count near the budget");
      csv << jobs[j].budget << ',' << r.name << ',' << r.family << ',' << r.note << ',' << r.steps_per_period
          << ",,,"  //
          << r.failed_in_period << ",,,\n";
      continue;
    }
    double early = 0.0, late = 0.0;
    for (const PeriodBlock& b : r.envelope) {
      if (b.first < 10) early = std::max(early, b.max_error);
      if (b.first * 10 >= periods) late = std::max(late, b.max_error);
      csv << jobs[j].budget << ',' << r.name << ',' << r.family << ',' << r.note << ',' << r.steps_per_period << ','
          << period / static_cast<double>(r.steps_per_period) << ',' << r.calls_per_period << ",0," << b.first << ','
          << b.last << ',' << b.max_error << '\n';
    }
    std::printf("| %.0f | %s | %zu | %.0f | %.2e | %.2e | %.2f | %.1f |\n", jobs[j].budget, label.c_str(),
                r.steps_per_period, r.calls_per_period, early, late, slope_of_last_two_decades(r.envelope, periods),
                r.seconds);
  }
  return csv ? 0 : 1;
}
