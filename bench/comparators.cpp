// The cost of the generic comparator steppers (core/include/nonsep/core/schemes/tao_extended_phase_space.hpp and
// gauss_legendre.hpp) against the same methods hand-written for the paper's 1D model, on one trajectory and on an
// ensemble of 1024, in TTV form, dt = 1e-3, omega = 20:
//
//   tao 2:   TaoExtendedPhaseSpace (order 2) over a scalar loop of the same Strang step with the closed-form
//            dH/dq = 2 q u^2, dH/dp = 2 p (1 + q^2) u, u = 1 + p^2/2, and the same first-same-as-last reuse;
//   gauss 2: GaussLegendre (s = 1, implicit midpoint) over a scalar loop of the same fixed-point iteration and
//            stopping rule.
//
// The hand-written loops do the floating-point operations of the generic code in the same order (the gradient of H
// composed from grad T, Hess V, Hess T and d3V as hamiltonian_gradient.hpp composes it), so their end states must
// agree bit for bit: the program checks that and exits with status 1 otherwise, so a faster but different loop
// cannot pass. What the ratio measures is the price of generality: batched model calls through spans, the
// gradient assembled from four model calls into work arrays, per-state bookkeeping of the iteration.
//
// It then prints the cost per step in full gradients of H (EvaluationCounts::grad_H) of Tao and Gauss of orders 2,
// 4, 6 over the quarter period of paper1d from (2, 0) at dt = T/16 .. T/1024, with the phase error at the end
// against the exact end point (docs/work-precision.md, "Methods and their cost"), and, for Gauss with 2 to 8 stages,
// the fewest grad H that meet a phase tolerance (1e-6 .. 1e-13) over one period of paper1d from (1, 0) and (2, 0)
// (the steps on a ladder of ratio 2^(1/4)): where each order wins.
//
// Usage: nonsep_bench_comparators [--smoke]   (--smoke: short runs, a few seconds; the ctest bench.comparators.smoke)
// Times are medians of 5 repetitions on a shared machine: reported, not enforced.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/reference/paper1d_exact.hpp"

namespace {

using Clock = std::chrono::steady_clock;
constexpr double dt = 1e-3, omega = 20.0;

// T = p + p^3/6, V = q^2/2 + q^4/12 (paper, eq. algham), with the derivatives the comparators need.
struct Paper1D {
  std::size_t dimension() const { return 1; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 1.0 + 0.5 * p[b] * p[b];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = q[b] + q[b] * q[b] * q[b] / 3.0;
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = p[b];
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 1.0 + q[b] * q[b];
  }
  void d3T(std::span<const double>, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = u[b] * u[b];
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    for (std::size_t b = 0; b < count; ++b) out[b] = 2.0 * q[b] * u[b] * u[b];
  }
};

// grad H_TTV in the generic code's operation order: dH/dq = d3V(q, u), dH/dp = 2 (T''(p) (V''(q) u)), u = T'(p).
inline void grad_H(double q, double p, double& dq, double& dp) {
  const double u = 1.0 + 0.5 * p * p;
  dq = 2.0 * q * u * u;
  dp = 2.0 * (p * ((1.0 + q * q) * u));
}

// Tao's order-2 step, one trajectory (q, p) with its copy (x, y) and the cached gradient at (q, y).
struct HandTao {
  double q, p, x, y, a_dq = 0, a_dp = 0, cached_q = std::nan(""), cached_y = std::nan("");
  void step() {
    const double h = dt / 2.0;
    if (!(std::memcmp(&cached_q, &q, sizeof q) == 0 && std::memcmp(&cached_y, &y, sizeof y) == 0)) {
      grad_H(q, y, a_dq, a_dp);
      cached_q = q, cached_y = y;
    }
    p -= h * a_dq, x += h * a_dp;
    double b_dq, b_dp;
    grad_H(x, p, b_dq, b_dp);
    q += h * b_dp, y -= h * b_dq;
    const double c = std::cos(2.0 * omega * dt), s = std::sin(2.0 * omega * dt);
    const double sum_q = q + x, sum_p = p + y, d_q = q - x, d_p = p - y;
    const double turned_q = c * d_q + s * d_p, turned_p = -s * d_q + c * d_p;
    q = (sum_q + turned_q) / 2.0, x = (sum_q - turned_q) / 2.0;
    p = (sum_p + turned_p) / 2.0, y = (sum_p - turned_p) / 2.0;
    grad_H(x, p, b_dq, b_dp);
    q += h * b_dp, y -= h * b_dq;
    grad_H(q, y, a_dq, a_dp);
    cached_q = q, cached_y = y;
    p -= h * a_dq, x += h * a_dp;
  }
};

// The implicit midpoint rule by the fixed-point iteration, starting values and stopping rule of gauss_legendre.hpp
// (s = 1: hb = dt, mu = nu = 1/2, so that L = dt f, Z = L / 2, z' = z + L compensated, and the next step starts from
// Z = L / 2 of this one's L when it continues it). Returns false when the iteration fails.
struct HandMidpoint {
  double q, p, last_q = 0.0, last_p = 0.0, Lq = 0.0, Lp = 0.0, error_q = 0.0, error_p = 0.0;
  bool have_last = false;
  static void add(double& z, double increment, double& error) {
    increment += error;
    const double sum = z + increment, increment_part = sum - z;
    error = (z - (sum - increment_part)) + (increment - increment_part);
    z = sum;
  }
  bool step() {
    const double eps = std::numeric_limits<double>::epsilon();
    const bool continues = have_last && last_q == q && last_p == p;
    if (!continues) error_q = error_p = 0.0;
    double zq = continues ? 0.5 * Lq : 0.0, zp = continues ? 0.5 * Lp : 0.0;
    double last = std::numeric_limits<double>::infinity();
    for (int m = 0; m < nonsep::GaussLegendre::default_max_iterations; ++m) {
      double dq, dp;
      grad_H(q + zq, p + zp, dq, dp);
      const double lq = dt * dp, lp = dt * -dq;
      const double nq = 0.5 * lq, np = 0.5 * lp;
      if (!std::isfinite(nq) || !std::isfinite(np)) return false;
      const double change = std::max(std::abs(nq - zq), std::abs(np - zp));
      const double scale = std::max({std::abs(q), std::abs(p), std::abs(nq), std::abs(np)});
      zq = nq, zp = np;
      const double relative = scale > 0.0 ? change / scale : 0.0;
      if (relative <= eps || (relative >= last && relative <= 64 * eps)) {
        add(q, lq, error_q);
        add(p, lp, error_p);
        last_q = q, last_p = p, Lq = lq, Lp = lp, have_last = true;
        return true;
      }
      last = relative;
    }
    return false;
  }
};

double median_seconds(const std::function<void()>& run) {
  std::vector<double> times;
  for (int r = 0; r < 5; ++r) {
    const auto start = Clock::now();
    run();
    times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[2];
}

nonsep::PhaseSpaceBatch initial(std::size_t count) {
  nonsep::PhaseSpaceBatch x(1, count);
  for (std::size_t b = 0; b < count; ++b) x.q()[b] = 0.2 + 1.6 * static_cast<double>(b) / static_cast<double>(count);
  return x;
}

// True when a and b are equal bit for bit; otherwise prints the largest difference.
bool same(const nonsep::PhaseSpaceBatch& a, const nonsep::PhaseSpaceBatch& b, const char* method) {
  if (a == b) return true;
  double largest = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    largest = std::max({largest, std::abs(a.q()[i] - b.q()[i]), std::abs(a.p()[i] - b.p()[i])});
  std::printf("%s: the generic stepper and the hand-written loop differ by up to %.3g\n", method, largest);
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const bool smoke = argc > 1 && std::string(argv[1]) == "--smoke";
  bool agree = true;
  std::printf("%-8s %9s %8s %16s %16s %7s\n", "method", "ensemble", "steps", "generic ns/step", "hand ns/step",
              "ratio");
  for (const std::size_t count : {std::size_t{1}, std::size_t{1024}}) {
    const int steps = static_cast<int>((count == 1 ? 200000 : 400) * (smoke ? 0.05 : 1.0));
    const double per = 1e9 / (static_cast<double>(steps) * static_cast<double>(count));
    nonsep::PhaseSpaceBatch generic, hand;
    // Tao, order 2.
    const double tao_generic = median_seconds([&] {
      generic = initial(count);
      nonsep::TaoExtendedPhaseSpace tao(nonsep::HamiltonianForm::TTV, 2, omega);
      for (int s = 0; s < steps; ++s) tao.step(Paper1D{}, generic, dt);
    });
    const double tao_hand = median_seconds([&] {
      hand = initial(count);
      std::vector<HandTao> states(count);
      for (std::size_t b = 0; b < count; ++b) states[b] = {hand.q()[b], hand.p()[b], hand.q()[b], hand.p()[b]};
      for (int s = 0; s < steps; ++s)
        for (auto& state : states) state.step();
      for (std::size_t b = 0; b < count; ++b) hand.q()[b] = states[b].q, hand.p()[b] = states[b].p;
    });
    agree &= same(generic, hand, "tao 2");
    std::printf("%-8s %9zu %8d %16.1f %16.1f %7.2f\n", "tao 2", count, steps, tao_generic * per, tao_hand * per,
                tao_generic / tao_hand);
    // Gauss, s = 1.
    const double gauss_generic = median_seconds([&] {
      generic = initial(count);
      nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, 2);
      for (int s = 0; s < steps; ++s) gauss.step(Paper1D{}, generic, dt);
    });
    const double gauss_hand = median_seconds([&] {
      hand = initial(count);
      std::vector<HandMidpoint> states(count);
      for (std::size_t b = 0; b < count; ++b) states[b] = {hand.q()[b], hand.p()[b]};
      for (int s = 0; s < steps; ++s)
        for (auto& state : states)
          if (!state.step()) std::abort();
      for (std::size_t b = 0; b < count; ++b) hand.q()[b] = states[b].q, hand.p()[b] = states[b].p;
    });
    agree &= same(generic, hand, "gauss 2");
    std::printf("%-8s %9zu %8d %16.1f %16.1f %7.2f\n", "gauss 2", count, steps, gauss_generic * per, gauss_hand * per,
                gauss_generic / gauss_hand);
  }
  const auto exact = nonsep::reference::paper1d_quarter(2.0);
  std::printf("\n%-8s %9s %13s %13s %12s\n", "method", "steps", "grad H/step", "iterations", "phase error");
  for (const int order : {2, 4, 6})
    for (const int steps : {16, 64, 256, 1024}) {
      const double h = exact.period / steps;
      auto x = nonsep::PhaseSpaceBatch::single(std::vector<double>{2.0}, std::vector<double>{0.0}), y = x;
      nonsep::TaoExtendedPhaseSpace tao(nonsep::HamiltonianForm::TTV, order, omega);
      nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, order);
      for (int s = 0; s < steps; ++s) {
        tao.step(Paper1D{}, x, h);
        gauss.step(Paper1D{}, y, h);
      }
      const double tao_cost = static_cast<double>(tao.evaluations().grad_H) / steps;
      const double gauss_cost = static_cast<double>(gauss.evaluations().grad_H) / steps;
      std::printf("tao %d    %9d %13.2f %13s %12.3g\n", order, steps, tao_cost, "-",
                  std::hypot(x.q()[0], x.p()[0] - exact.p_final));
      std::printf("gauss %d  %9d %13.2f %13.2f %12.3g\n", order, steps, gauss_cost, gauss_cost / (order / 2),
                  std::hypot(y.q()[0], y.p()[0] - exact.p_final));
    }
  std::printf("\nfewest grad H (steps) of Gauss over one period of paper1d to meet a phase tolerance\n%-4s %-7s", "q0",
              "tol");
  const int stage_counts[] = {2, 3, 4, 5, 6, 8};
  for (const int stages : stage_counts) std::printf(" %14s", ("gauss " + std::to_string(2 * stages)).c_str());
  std::printf("\n");
  for (const double q0 : {1.0, 2.0}) {
    const double period = 4 * nonsep::reference::paper1d_quarter(q0).period;
    for (const double tolerance : {1e-6, 1e-8, 1e-10, 1e-12, 1e-13}) {
      std::printf("%-4g %-7g", q0, tolerance);
      for (const int stages : stage_counts) {
        std::string cell = "-";
        for (int k = 0; k < (smoke ? 40 : 80); ++k) {
          const int steps = static_cast<int>(std::ceil(std::pow(2.0, k / 4.0)));
          nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, 2 * stages);
          auto x = nonsep::PhaseSpaceBatch::single(std::vector<double>{q0}, std::vector<double>{0.0});
          double error = std::numeric_limits<double>::infinity();
          try {
            for (int s = 0; s < steps; ++s) gauss.step(Paper1D{}, x, period / steps);
            error = std::hypot(x.q()[0] - q0, x.p()[0]);
          } catch (const nonsep::ModelError&) {
            // too large a step for the iteration: the next rung
          }
          if (error <= tolerance) {
            cell = std::to_string(gauss.evaluations().grad_H) + " (" + std::to_string(steps) + ")";
            break;
          }
        }
        std::printf(" %14s", cell.c_str());
      }
      std::printf("\n");
    }
  }
  if (!agree) {
    std::printf("the generic steppers and the hand-written loops disagree\n");
    return 1;
  }
  std::printf("end states agree bit for bit\n");
  return 0;
}
