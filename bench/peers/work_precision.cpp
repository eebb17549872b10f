// Work versus precision of nonsep's schemes (Chin's and the comparators tao 2/4/6, implicit midpoint, gauss 4/6)
// against the integrators a user would otherwise pick for a non-separable Hamiltonian (GSL rk2imp/rk4imp at fixed step,
// Odeint runge_kutta4 and runge_kutta_dopri5), plus the long-time energy drift of basic, triplet 4/3 and runge_kutta4.
//
// Usage: nonsep_bench_work_precision [--smoke] [--out DIR]
//   --smoke   a tiny ladder (seconds; for CI)
//   --out     where work_precision.csv and energy_drift.csv go (default: the current directory)
// Prints two target tables (all methods; symplectic methods only): for each problem, error kind (relative
// energy, phase space) and target, the wall time of the cheapest nonsep run meeting it, of the cheapest peer
// run meeting it, and their ratio. docs/performance-peers.md has the measured tables and how to plot the CSVs.
//
// Problems (benchmark_problems.hpp), both solved by nonsep in TTV form:
//   paper1d      from (q, p) = (2, 0) to the quarter period, exact end point (0, p_final) by quadrature;
//   tao_product  from (-3, 0) to t = 5, end point from an RKF78 reference at tolerance 1e-14, whose own error
//                is estimated against tolerance 1e-13 (targets within 10x of it are "not measurable").
// Timing: each run is repeated in a batch lasting at least min_sample_seconds; the reported time is the median
// over `repetitions` batches of (batch time / runs in the batch), on std::chrono::steady_clock.
// Ladders: fixed-step methods run at step counts 2, 2f, 2f^2, ... and dopri5 at tolerances 1e-3, 1e-3/g, ...
// until a run exceeds max_run_seconds, both errors are below stop_error, or the errors stop improving (Policy).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "benchmark_problems.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/reference/hamiltonian_flow.hpp"
#include "nonsep/reference/paper1d_exact.hpp"
#include "odeint_methods.hpp"
#include "peer_result.hpp"
#ifdef NONSEP_BENCH_HAVE_GSL
#include "gsl_gauss_methods.hpp"
#endif

namespace nonsep::bench {
namespace {

constexpr double targets[] = {1e-4, 1e-6, 1e-8, 1e-10};

struct Options {
  bool smoke = false;
  std::filesystem::path out = ".";
};

struct Policy {
  double ladder_factor;             // ratio of successive step counts
  double tolerance_factor;          // ratio of successive dopri5 tolerances
  int repetitions;                  // timed batches per setting; the median is reported
  double min_sample_seconds;        // each batch repeats the run until it lasts this long
  double max_run_seconds;           // a ladder stops after the first run longer than this
  std::size_t max_steps;            // ... or beyond this many steps
  double stop_error;                // ... or once both errors are below this
  std::vector<std::string> orders;  // orders of triplet and MPE
  std::vector<double> extra_t2;     // t2 values tried besides the default (triplet and MPE)
  std::size_t drift_periods, drift_steps_per_period;
};

Policy smoke_policy() { return {4.0, 100.0, 5, 2e-4, 2e-3, 1u << 14, 1e-11, {"4/3", "4"}, {}, 100, 512}; }
Policy full_policy() {
  return {std::sqrt(2.0), std::sqrt(10.0), 5,  5e-3, 0.1, 1u << 26, 1e-11, {"4/3", "2", "8/3", "10/3", "4"},
          {-1.5, -2.5},   10000,           512};
}

// One problem as the benchmark sees it: start, end time, the exact (or reference) end point and how well that
// end point is known.
struct Setup {
  std::string name;
  double q0, p0, t_end;
  double q_end, p_end;
  double energy;           // H(q0, p0)
  double end_point_error;  // estimated error of (q_end, p_end)
};

struct Row {
  std::string method, family, problem, setting;
  double dt_or_tolerance;
  double wall_seconds;
  double energy_error, phase_error;
  std::uint64_t evaluations, jacobian_evaluations;
  bool succeeded;
  bool symplectic;  // basic, triplet, tao (on the extended phase space), implicit midpoint, gauss, GSL's Gauss methods
};

volatile double sink = 0.0;  // keeps the timed runs from being optimised away

// The median over policy.repetitions batches of the time of one run; also returns the run's result.
std::pair<RunResult, double> time_run(const std::function<RunResult()>& run, const Policy& policy,
                                      double* first_run_seconds) {
  using clock = std::chrono::steady_clock;
  auto start = clock::now();
  RunResult result = run();
  const double first = std::chrono::duration<double>(clock::now() - start).count();
  if (first_run_seconds) *first_run_seconds = first;
  const auto per_batch =
      static_cast<std::size_t>(std::clamp(std::ceil(policy.min_sample_seconds / std::max(first, 1e-9)), 1.0, 1e6));
  std::vector<double> samples;
  for (int r = 0; r < policy.repetitions; ++r) {
    start = clock::now();
    for (std::size_t i = 0; i < per_batch; ++i) sink = sink + run().q;
    samples.push_back(std::chrono::duration<double>(clock::now() - start).count() / static_cast<double>(per_batch));
  }
  std::nth_element(samples.begin(), samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2), samples.end());
  return {result, samples[samples.size() / 2]};
}

template <class P>
Row make_row(const Setup& setup, std::string method, std::string family, std::string setting, double dt_or_tolerance,
             const RunResult& r, double seconds) {
  const double energy_error = std::abs(P::H(r.q, r.p) - setup.energy) / setup.energy;
  const double phase_error = std::hypot(r.q - setup.q_end, r.p - setup.p_end);
  return {method,
          std::move(family),
          setup.name,
          std::move(setting),
          dt_or_tolerance,
          seconds,
          r.succeeded ? energy_error : std::numeric_limits<double>::quiet_NaN(),
          r.succeeded ? phase_error : std::numeric_limits<double>::quiet_NaN(),
          r.evaluations,
          r.jacobian_evaluations,
          r.succeeded,
          method.starts_with("basic") || method.starts_with("triplet") || method.starts_with("gsl") ||
              method.starts_with("tao") || method.starts_with("gauss") || method == "implicit midpoint"};
}

// Stops a ladder: after a long run, once both errors are below stop_error, or, once converging, when neither
// error has improved by 2x over the last 4 successful settings (the method has hit its rounding or
// Newton-tolerance floor).
class LadderStop {
 public:
  explicit LadderStop(const Policy& policy) : policy_(policy) {}
  bool after(const Row& row, double first_run_seconds) {
    if (first_run_seconds > policy_.max_run_seconds) return true;
    if (!row.succeeded) return false;
    if (row.energy_error < policy_.stop_error && row.phase_error < policy_.stop_error) return true;
    // Coarse settings may diverge or be far from converged; the floor is looked for only once both errors
    // have come below 0.1.
    converging_ = converging_ || (row.energy_error < 0.1 && row.phase_error < 0.1);
    if (!converging_) return false;
    history_.push_back(std::min(row.energy_error, best_energy_) < best_energy_ / 2 ||
                       std::min(row.phase_error, best_phase_) < best_phase_ / 2);
    if (history_.back()) {
      best_energy_ = std::min(best_energy_, row.energy_error);
      best_phase_ = std::min(best_phase_, row.phase_error);
    }
    return history_.size() >= 5 && std::none_of(history_.end() - 4, history_.end(), [](bool b) { return b; });
  }

 private:
  const Policy& policy_;
  double best_energy_ = std::numeric_limits<double>::infinity();
  double best_phase_ = std::numeric_limits<double>::infinity();
  std::vector<bool> history_;
  bool converging_ = false;
};

// Runs run_at at step counts first, first*f, first*f^2, ... (rounded, strictly increasing) until LadderStop says
// stop; run_at returns the row of one setting and the duration of its first (untimed) run.
void step_ladder(const Policy& policy, std::size_t first,
                 const std::function<Row(std::size_t steps, double* first_run_seconds)>& run_at,
                 std::vector<Row>& rows) {
  LadderStop stop(policy);
  std::size_t previous = 0;
  for (double n = static_cast<double>(first); n <= static_cast<double>(policy.max_steps); n *= policy.ladder_factor) {
    const auto steps = static_cast<std::size_t>(std::llround(n));
    if (steps == previous) continue;
    previous = steps;
    double seconds = 0.0;
    rows.push_back(run_at(steps, &seconds));
    if (stop.after(rows.back(), seconds)) break;
  }
}

std::string format_double(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

template <class P>
void run_problem(const Setup& setup, const Policy& policy, std::vector<Row>& rows) {
  std::cout << "[" << setup.name << "] nonsep schemes" << std::endl;
  std::vector<IntegratorSpec> specs{{"basic", ChinOptions{Fraction(2, 3)}}};
  for (const auto& scheme : {"triplet", "mpe"})
    for (const auto& order : policy.orders) {
      specs.push_back({scheme, ChinOptions{Fraction::parse(order)}});
      for (const double t2 : policy.extra_t2) specs.push_back({scheme, ChinOptions{Fraction::parse(order), t2}});
    }
  for (const auto& spec : specs) {
    const ChinOptions& options = std::get<ChinOptions>(spec.options);
    const std::string method = spec.scheme == "basic" ? "basic" : spec.scheme + " " + options.order.to_string();
    const std::string t2 = options.t2 == ChinCoefficients::default_t2() ? "default" : format_double(options.t2);
    step_ladder(
        policy, 2,
        [&](std::size_t steps, double* first) -> Row {
          const double dt = setup.t_end / static_cast<double>(steps);
          auto run = [&] {
            const BatchedModel<P> model;
            Integrator integrator(spec);
            const double q[1] = {setup.q0}, p[1] = {setup.p0};
            auto x = PhaseSpaceBatch::single(q, p);
            for (std::size_t i = 0; i < steps; ++i) integrator.step(model, x, dt);
            const auto& counts = integrator.evaluations();
            return RunResult{x.q()[0], x.p()[0], counts.grad_T + counts.grad_V, 0, true};
          };
          const auto [result, seconds] = time_run(run, policy, first);
          return make_row<P>(setup, method, "nonsep", "steps=" + std::to_string(steps) + " t2=" + t2, dt, result,
                             seconds);
        },
        rows);
  }

  // The comparators, through the same Integrator; their `evaluations` count grad H (a peer's f is the same thing).
  std::vector<std::pair<std::string, IntegratorSpec>> comparators;
  for (const int order : {2, 4, 6})
    comparators.push_back({"tao " + std::to_string(order), {"tao", TaoOptions{Fraction(order)}}});
  for (const int stages : {1, 2, 3}) {
    const IntegratorSpec spec{"gauss", GaussOptions{stages}};
    comparators.push_back({stages == 1 ? "implicit midpoint" : "gauss " + std::to_string(2 * stages), spec});
  }
  for (const auto& [method, spec] : comparators)
    step_ladder(
        policy, 2,
        [&](std::size_t steps, double* first) -> Row {
          const double dt = setup.t_end / static_cast<double>(steps);
          auto run = [&] {
            Integrator integrator(spec);
            const double q[1] = {setup.q0}, p[1] = {setup.p0};
            auto x = PhaseSpaceBatch::single(q, p);
            try {
              for (std::size_t i = 0; i < steps; ++i) integrator.step(BatchedModel<P>{}, x, dt);
            } catch (const ModelError&) {  // a Gauss iteration that does not contract at this dt
              return RunResult{x.q()[0], x.p()[0], integrator.evaluations().grad_H, 0, false};
            }
            return RunResult{x.q()[0], x.p()[0], integrator.evaluations().grad_H, 0, true};
          };
          const auto [result, seconds] = time_run(run, policy, first);
          return make_row<P>(setup, method, "nonsep", "steps=" + std::to_string(steps), dt, result, seconds);
        },
        rows);

  std::cout << "[" << setup.name << "] peers" << std::endl;
  step_ladder(
      policy, 2,
      [&](std::size_t steps, double* first) -> Row {
        auto run = [&] { return odeint_runge_kutta4<P>(setup.q0, setup.p0, setup.t_end, steps); };
        const auto [result, seconds] = time_run(run, policy, first);
        return make_row<P>(setup, "odeint runge_kutta4", "peer", "steps=" + std::to_string(steps),
                           setup.t_end / static_cast<double>(steps), result, seconds);
      },
      rows);
  {
    LadderStop stop(policy);
    for (double tolerance = 1e-3; tolerance >= 1e-15; tolerance /= policy.tolerance_factor) {
      double first = 0.0;
      auto run = [&] { return odeint_dopri5<P>(setup.q0, setup.p0, setup.t_end, tolerance); };
      const auto [result, seconds] = time_run(run, policy, &first);
      rows.push_back(make_row<P>(setup, "odeint runge_kutta_dopri5", "peer", "tol=" + format_double(tolerance),
                                 tolerance, result, seconds));
      if (stop.after(rows.back(), first)) break;
    }
  }
#ifdef NONSEP_BENCH_HAVE_GSL
  gsl_set_error_handler_off();  // failures come back as return codes and are recorded
  const std::pair<const char*, const gsl_odeiv2_step_type*> gsl_methods[] = {{"gsl rk2imp", gsl_odeiv2_step_rk2imp},
                                                                             {"gsl rk4imp", gsl_odeiv2_step_rk4imp}};
  for (const auto& [name, type] : gsl_methods) {
    for (const double tolerance : {1e-5, 1e-8, 1e-11, 1e-14}) {
      GslFixedStep<P> gsl(type, tolerance);
      step_ladder(
          policy, 2,
          [&](std::size_t steps, double* first) -> Row {
            auto run = [&] { return gsl.run(setup.q0, setup.p0, setup.t_end, steps); };
            const auto [result, seconds] = time_run(run, policy, first);
            return make_row<P>(setup, name, "peer",
                               "steps=" + std::to_string(steps) + " tol=" + format_double(tolerance),
                               setup.t_end / static_cast<double>(steps), result, seconds);
          },
          rows);
    }
  }
#endif
}

std::string csv_number(double x) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(10);
  s << x;
  return s.str();
}

void write_work_precision_csv(const std::filesystem::path& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "method,family,problem,setting,dt_or_tol,wall_seconds_median,energy_error,phase_error,evaluations,"
         "jacobian_evaluations,symplectic,status\n";
  for (const auto& r : rows)
    out << r.method << ',' << r.family << ',' << r.problem << ',' << r.setting << ',' << csv_number(r.dt_or_tolerance)
        << ',' << csv_number(r.wall_seconds) << ',' << csv_number(r.energy_error) << ',' << csv_number(r.phase_error)
        << ',' << r.evaluations << ',' << r.jacobian_evaluations << ',' << (r.symplectic ? "yes" : "no") << ','
        << (r.succeeded ? "ok" : "failed") << '\n';
  if (!out) throw std::runtime_error("could not write " + path.string());
}

// The cheapest successful row of `family` (and symplectic, if asked) whose error of the given kind is at most
// target.
const Row* cheapest(const std::vector<Row>& rows, const std::string& problem, const std::string& family,
                    bool symplectic_only, bool energy, double target) {
  const Row* best = nullptr;
  for (const auto& r : rows) {
    if (r.problem != problem || r.family != family || !r.succeeded || (symplectic_only && !r.symplectic)) continue;
    const double error = energy ? r.energy_error : r.phase_error;
    if (!(error <= target)) continue;
    if (!best || r.wall_seconds < best->wall_seconds) best = &r;
  }
  return best;
}

void print_target_table(const std::vector<Row>& rows, const std::vector<Setup>& setups, bool symplectic_only) {
  std::printf(
      "\nTarget table%s: wall time of the cheapest run meeting each target (median of repetitions);\n"
      "ratio = nonsep time / peer time (< 1: nonsep is faster).\n\n",
      symplectic_only ? ", symplectic methods only (nonsep basic, triplet, tao, implicit midpoint and gauss against "
                        "GSL rk2imp and rk4imp)"
                      : ", all methods");
  std::printf("| problem | error | target | cheapest nonsep | time [s] | cheapest peer | time [s] | ratio |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const auto& setup : setups) {
    for (const bool energy : {true, false}) {
      for (const double target : targets) {
        std::printf("| %s | %s | %.0e |", setup.name.c_str(), energy ? "energy" : "phase", target);
        if (!energy && target < 10.0 * setup.end_point_error) {
          std::printf(" not measurable (reference error %.1e) | | | | |\n", setup.end_point_error);
          continue;
        }
        const Row* ours = cheapest(rows, setup.name, "nonsep", symplectic_only, energy, target);
        const Row* peer = cheapest(rows, setup.name, "peer", symplectic_only, energy, target);
        auto cell = [](const Row* r) {
          if (!r)
            std::printf(" not reached | |");
          else
            std::printf(" %s (%s) | %.3g |", r->method.c_str(), r->setting.c_str(), r->wall_seconds);
        };
        cell(ours);
        cell(peer);
        if (ours && peer)
          std::printf(" %.3g |\n", ours->wall_seconds / peer->wall_seconds);
        else
          std::printf(" - |\n");
      }
    }
  }
}

// Energy drift over many periods of paper1d from (2, 0): basic, triplet 4/3 and runge_kutta4 at the same dt.
// Writes, per method and period, |relative energy error| at the end of the period and its maximum over the
// period's steps; prints the maximum over the first and the last 10% of the periods.
void energy_drift(const Policy& policy, const std::filesystem::path& path) {
  const double q0 = 2.0;
  const auto quarter = reference::paper1d_quarter(q0);
  const double period = 4.0 * quarter.period;
  const std::size_t n = policy.drift_steps_per_period;
  const double dt = period / static_cast<double>(n);
  const double energy = quarter.energy;
  std::ofstream out(path);
  out.precision(10);
  out << "method,dt,period,time,energy_error_end,energy_error_max\n";
  std::printf("\nEnergy drift: paper1d from (2, 0), period %.10g, dt = period/%zu = %.4g, %zu periods\n", period, n, dt,
              policy.drift_periods);
  std::printf("| method | max rel. energy error, first 10%% of periods | last 10%% | ratio last/first |\n");
  std::printf("|---|---|---|---|\n");

  auto record = [&](const std::string& method, auto&& step) {
    double q = q0, p = 0.0;
    const std::size_t tenth = std::max<std::size_t>(1, policy.drift_periods / 10);
    double first_max = 0.0, last_max = 0.0;
    for (std::size_t k = 1; k <= policy.drift_periods; ++k) {
      double period_max = 0.0, e = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        step(q, p);
        e = std::abs(Paper1D::H(q, p) - energy) / energy;
        if (std::isnan(e)) e = std::numeric_limits<double>::infinity();  // diverged
        period_max = std::max(period_max, e);
      }
      out << method << ',' << dt << ',' << k << ',' << static_cast<double>(k) * period << ',' << e << ',' << period_max
          << '\n';
      if (k <= tenth) first_max = std::max(first_max, period_max);
      if (k > policy.drift_periods - tenth) last_max = std::max(last_max, period_max);
    }
    std::printf("| %s | %.3e | %.3e | %.3g |\n", method.c_str(), first_max, last_max, last_max / first_max);
  };

  const BatchedModel<Paper1D> model;
  for (const auto& [method, spec] :
       {std::pair<std::string, IntegratorSpec>{"basic", {"basic", ChinOptions{Fraction(2, 3)}}},
        {"triplet 4/3", {"triplet", ChinOptions{Fraction(4, 3)}}}}) {
    Integrator integrator(spec);
    PhaseSpaceBatch x(1, 1);
    record(method, [&](double& q, double& p) {
      x.q()[0] = q;
      x.p()[0] = p;
      integrator.step(model, x, dt);
      q = x.q()[0];
      p = x.p()[0];
    });
  }
  boost::numeric::odeint::runge_kutta4<OdeintState> rk4;
  std::uint64_t calls = 0;
  record("odeint runge_kutta4", [&](double& q, double& p) {
    OdeintState s{q, p};
    rk4.do_step(CountedHamiltonEquations<Paper1D>{&calls}, s, 0.0, dt);
    q = s[0];
    p = s[1];
  });
  if (!out) throw std::runtime_error("could not write " + path.string());
}

// tao_product's reference end point and an estimate of its error (see the file comment).
Setup tao_product_setup() {
  const double q0 = -3.0, p0 = 0.0, t_end = 5.0;
  auto rhs = [](const std::vector<double>& x, std::vector<double>& dxdt) {
    dxdt[0] = TaoProduct::dH_dp(x[0], x[1]);
    dxdt[1] = -TaoProduct::dH_dq(x[0], x[1]);
  };
  const auto fine = reference::hamiltonian_flow(rhs, {q0, p0}, t_end, 1e-14);
  const auto coarse = reference::hamiltonian_flow(rhs, {q0, p0}, t_end, 1e-13);
  const double energy = TaoProduct::H(q0, p0);
  const double difference = std::hypot(fine[0] - coarse[0], fine[1] - coarse[1]);
  const double energy_error = std::abs(TaoProduct::H(fine[0], fine[1]) - energy) / energy;
  std::printf(
      "tao_product reference at t = %g: (q, p) = (%.16g, %.16g); |tol 1e-14 - tol 1e-13| = %.2e, "
      "relative energy error %.2e\n",
      t_end, fine[0], fine[1], difference, energy_error);
  const double error = std::max({difference, energy_error * std::hypot(fine[0], fine[1]), 1e-16});
  return {TaoProduct::name, q0, p0, t_end, fine[0], fine[1], energy, error};
}

Setup paper1d_setup() {
  const double q0 = 2.0;
  const auto quarter = reference::paper1d_quarter(q0);
  // Cross-check of the quadrature against the RKF78 reference flow.
  auto rhs = [](const std::vector<double>& x, std::vector<double>& dxdt) {
    dxdt[0] = Paper1D::dH_dp(x[0], x[1]);
    dxdt[1] = -Paper1D::dH_dq(x[0], x[1]);
  };
  const auto flow = reference::hamiltonian_flow(rhs, {q0, 0.0}, quarter.period, 1e-14);
  const double disagreement = std::hypot(flow[0], flow[1] - quarter.p_final);
  std::printf("paper1d exact end point at the quarter period %.16g: (0, %.16g); RKF78 reference differs by %.2e\n",
              quarter.period, quarter.p_final, disagreement);
  return {Paper1D::name, q0, 0.0, quarter.period, 0.0, quarter.p_final, quarter.energy, 1e-15};
}

int run(const Options& options) {
  bool derivatives_ok = true;
  for (const auto& failures : {check_derivatives<Paper1D>(), check_derivatives<TaoProduct>()})
    for (const auto& failure : failures) {
      std::cerr << "derivative check failed: " << failure << '\n';
      derivatives_ok = false;
    }
  if (!derivatives_ok) {
    std::cerr << "nonsep_bench_work_precision: the hand-derived derivatives are wrong; aborting\n";
    return 1;
  }
  std::cout << "derivatives of paper1d and tao_product agree with central differences" << std::endl;
#ifndef NONSEP_BENCH_HAVE_GSL
  std::cout << "note: built without GSL; the GSL peers rk2imp and rk4imp are skipped" << std::endl;
#endif

  const Policy policy = options.smoke ? smoke_policy() : full_policy();
  std::filesystem::create_directories(options.out);
  const std::vector<Setup> setups{paper1d_setup(), tao_product_setup()};
  std::vector<Row> rows;
  run_problem<Paper1D>(setups[0], policy, rows);
  run_problem<TaoProduct>(setups[1], policy, rows);
  write_work_precision_csv(options.out / "work_precision.csv", rows);
  print_target_table(rows, setups, false);
  print_target_table(rows, setups, true);
  energy_drift(policy, options.out / "energy_drift.csv");
  std::printf("\nwrote %s and %s\n", (options.out / "work_precision.csv").c_str(),
              (options.out / "energy_drift.csv").c_str());
  return 0;
}

}  // namespace
}  // namespace nonsep::bench

int main(int argc, char** argv) {
  nonsep::bench::Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--smoke") {
      options.smoke = true;
    } else if (arg == "--out" && i + 1 < argc) {
      options.out = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      std::cout << "usage: nonsep_bench_work_precision [--smoke] [--out DIR]\n"
                   "  --smoke    tiny ladders, a few seconds (CI)\n"
                   "  --out DIR  directory for work_precision.csv and energy_drift.csv (default .)\n";
      return 0;
    } else {
      std::cerr << "nonsep_bench_work_precision: unknown argument '" << arg << "' (try --help)\n";
      return 2;
    }
  }
  try {
    return nonsep::bench::run(options);
  } catch (const std::exception& e) {
    std::cerr << "nonsep_bench_work_precision: " << e.what() << '\n';
    return 1;
  }
}
