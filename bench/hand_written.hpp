#pragma once
// The physical limit the host is measured against (bench/performance.cpp): the basic step of eq. (expalg) on the
// paper's 1D model written out by hand, nine stages with the gradients inline, no Integrator, no batch types, no
// plugin. Form TTV, paper1d: grad T(p) = 1 + p^2/2, grad V(q) = q + q^3/3 (eq. algham).
//
//   p -= v2 eps V'(q); q += t2 eps T'(p); p -= v1 eps V'(q); q += t1 eps T'(p); p -= v0 eps V'(q);
//   q += t1 eps T'(p); p -= v1 eps V'(q); q += t2 eps T'(p); p -= v2 eps V'(q)
//
// with eps = cbrt(dt), t1 = -t2, v1 = 1/t2^2, v2 = -v1/2, v0 = -2 (v1 + v2). First-same-as-last: V'(q) of the
// last stage is kept for the first stage of the next step (4 T' + 4 V' per step).
// The operations are the ones ChinBasicStep and the shipped paper1d plugin do, in the same order (h = (-c) eps,
// y += h g; T' = 1 + 0.5 p p; V' = q (1 + q q / 3)), so the results are equal bit for bit as long as the compiler
// contracts nothing into fused multiply-adds (x86-64 without -march: no FMA instructions exist). With
// -march=native, GCC may fuse (C++ defaults to -ffp-contract=fast) differently here and in the plugin; the
// benchmark then checks closeness instead and says so.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace bench {

struct HandWrittenStep {
  double v2, t2, v1, t1, v0;  // each already multiplied by eps, kicks with their minus sign

  HandWrittenStep(double dt, double t2_free) {
    const double eps = std::cbrt(dt);
    const double c1 = 1.0 / (t2_free * t2_free), c2 = -c1 / 2.0, c0 = -2.0 * (c1 + c2);
    v2 = -c2 * eps;
    v1 = -c1 * eps;
    v0 = -c0 * eps;
    t2 = t2_free * eps;
    t1 = -t2_free * eps;
  }
};

inline double grad_T(double p) { return 1.0 + 0.5 * p * p; }
inline double grad_V(double q) { return q * (1.0 + q * q / 3.0); }

// One basic step of (x, y) with g = V'(x) on entry and on exit.
template <class GradT, class GradV>
inline void hand_written_step(const HandWrittenStep& c, double& x, double& y, double& g, GradT grad_T, GradV grad_V) {
  y += c.v2 * g;
  x += c.t2 * grad_T(y);
  g = grad_V(x);
  y += c.v1 * g;
  x += c.t1 * grad_T(y);
  g = grad_V(x);
  y += c.v0 * g;
  x += c.t1 * grad_T(y);
  g = grad_V(x);
  y += c.v1 * g;
  x += c.t2 * grad_T(y);
  g = grad_V(x);
  y += c.v2 * g;
}

// `steps` basic steps of one trajectory (q, p), in place. The gradients are paper1d's inline ones unless others are
// given (abi_floor.hpp's control passes functions of a plugin, called by value).
template <class GradT = double (*)(double), class GradV = double (*)(double)>
inline void hand_written_run(const HandWrittenStep& c, double& q, double& p, std::uint64_t steps,
                             GradT grad_T = bench::grad_T, GradV grad_V = bench::grad_V) {
  double x = q, y = p, g = grad_V(x);
  for (std::uint64_t k = 0; k < steps; ++k) hand_written_step(c, x, y, g, grad_T, grad_V);
  q = x;
  p = y;
}

// Triplet composition 4/3 (eq. sym43) of the hand-written step, one trajectory: each step the basic steps of
// dt/(2-s), -s dt/(2-s), dt/(2-s), s = 2^(3/5), with V' carried from one to the next.
inline void hand_written_triplet_run(double dt, double t2, double& q, double& p, std::uint64_t steps) {
  const double s = std::pow(2.0, 3.0 / 5.0), outer_dt = dt / (2.0 - s);
  const HandWrittenStep outer(outer_dt, t2), inner(-s * outer_dt, t2);
  double x = q, y = p, g = grad_V(x);
  for (std::uint64_t k = 0; k < steps; ++k) {
    hand_written_step(outer, x, y, g, bench::grad_T, bench::grad_V);
    hand_written_step(inner, x, y, g, bench::grad_T, bench::grad_V);
    hand_written_step(outer, x, y, g, bench::grad_T, bench::grad_V);
  }
  q = x;
  p = y;
}

// Multi-product expansion of m terms (eqs. mpe43, mpe63), one trajectory: each step, term k = m..1 takes k basic
// steps of dt/k from the step's start (V' at the start shared), and the result is y_m + sum_k c_k (y_k - y_m);
// V' at the combined point is evaluated anew. `weights` are c_1..c_m.
inline void hand_written_mpe_run(double dt, double t2, const std::vector<double>& weights, double& q, double& p,
                                 std::uint64_t steps) {
  const std::size_t m = weights.size();
  std::vector<HandWrittenStep> term;
  for (std::size_t k = 1; k <= m; ++k) term.emplace_back(dt / static_cast<double>(k), t2);
  double x = q, y = p, g = grad_V(x);
  for (std::uint64_t n = 0; n < steps; ++n) {
    double sum_x = 0, sum_y = 0, last_x = 0, last_y = 0;
    for (std::size_t k = m; k >= 1; --k) {
      double tx = x, ty = y, tg = g;
      for (std::size_t r = 0; r < k; ++r) hand_written_step(term[k - 1], tx, ty, tg, bench::grad_T, bench::grad_V);
      if (k == m) {
        sum_x = last_x = tx;
        sum_y = last_y = ty;
        continue;
      }
      sum_x += weights[k - 1] * (tx - last_x);
      sum_y += weights[k - 1] * (ty - last_y);
    }
    x = sum_x;
    y = sum_y;
    g = grad_V(x);
  }
  q = x;
  p = y;
}

// `steps` basic steps of `count` trajectories q[b], p[b], in place; g[b] holds V'(q[b]) (set here). The states
// are independent: one loop over them per step, nine stages each, which the compiler vectorizes at the SIMD
// width it is allowed (SSE2 by default, AVX2 and FMA with -march=native).
inline void hand_written_run(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count,
                             std::uint64_t steps) {
  for (std::size_t b = 0; b < count; ++b) g[b] = grad_V(q[b]);
  for (std::uint64_t k = 0; k < steps; ++k)
    for (std::size_t b = 0; b < count; ++b) {
      double x = q[b], y = p[b] + c.v2 * g[b];
      x += c.t2 * grad_T(y);
      y += c.v1 * grad_V(x);
      x += c.t1 * grad_T(y);
      y += c.v0 * grad_V(x);
      x += c.t1 * grad_T(y);
      y += c.v1 * grad_V(x);
      x += c.t2 * grad_T(y);
      const double gx = grad_V(x);
      q[b] = x;
      p[b] = y + c.v2 * gx;
      g[b] = gx;
    }
}

// The nine stages of one basic step, each a call: kick(h) for p += h V'(q), drift(h) for q += h T'(p) (which also
// evaluates V' at the new q for the next kick), with the coefficients of eq. (expalg) in their order.
template <class Kick, class Drift>
inline void basic_step_stages(const HandWrittenStep& c, Kick&& kick, Drift&& drift) {
  kick(c.v2);
  drift(c.t2);
  kick(c.v1);
  drift(c.t1);
  kick(c.v0);
  drift(c.t1);
  kick(c.v1);
  drift(c.t2);
  kick(c.v2);
}

// The same, written stage by stage: each of the nine stages one loop over all states (as the Integrator goes).
// Same operations per state, so the same bits as the loop above; which of the two is faster depends on the
// build (the loop above is latency-bound without wide SIMD, this one is throughput-bound), so the benchmark
// takes the faster as the limit.
inline void hand_written_run_staged(const HandWrittenStep& c, double* q, double* p, double* g, std::size_t count,
                                    std::uint64_t steps) {
  for (std::size_t b = 0; b < count; ++b) g[b] = grad_V(q[b]);
  const auto kick = [&](double h) {
    for (std::size_t b = 0; b < count; ++b) p[b] += h * g[b];
  };
  const auto drift = [&](double h) {
    for (std::size_t b = 0; b < count; ++b) {
      q[b] += h * grad_T(p[b]);
      g[b] = grad_V(q[b]);
    }
  };
  for (std::uint64_t k = 0; k < steps; ++k) basic_step_stages(c, kick, drift);
}

// The second derivatives of paper1d: T''(p) = p, V''(q) = 1 + q^2.
inline double hess_T(double p) { return p; }
inline double hess_V(double q) { return 1.0 + q * q; }

// `steps` basic steps of `count` trajectories q[b], p[b] with one tangent vector each, (dq[b], dp[b]): each flow's
// derivative applied at the point the flow starts from (kick: dp -= c eps V''(q) dq; drift: dq += c eps T''(p) dp),
// and every `renormalize_every` steps the vector normalised with ln |v| added to log_stretch[b] (Benettin's largest
// Lyapunov exponent: log_stretch / t). V'(q) and V''(q) of a step's last kick are kept for the next step's first.
// The limit for a run with one Lyapunov vector (analysis.lyapunov, vectors 1): one loop over the states per step.
inline void hand_written_tangent_run(const HandWrittenStep& c, double* q, double* p, double* dq, double* dp,
                                     double* log_stretch, std::size_t count, std::uint64_t steps,
                                     std::uint64_t renormalize_every) {
  std::vector<double> gradient(count), hessian(count);
  for (std::size_t b = 0; b < count; ++b) {
    gradient[b] = grad_V(q[b]);
    hessian[b] = hess_V(q[b]);
  }
  for (std::uint64_t k = 0; k < steps; ++k) {
    for (std::size_t b = 0; b < count; ++b) {
      double x = q[b], y = p[b], u = dq[b], w = dp[b], g = gradient[b], h = hessian[b];
      const auto kick = [&](double v) {
        y += v * g;
        w += v * h * u;
      };
      const auto drift = [&](double t) {
        x += t * grad_T(y);
        u += t * hess_T(y) * w;
        g = grad_V(x);
        h = hess_V(x);
      };
      basic_step_stages(c, kick, drift);
      q[b] = x;
      p[b] = y;
      dq[b] = u;
      dp[b] = w;
      gradient[b] = g;
      hessian[b] = h;
    }
    if ((k + 1) % renormalize_every == 0)
      for (std::size_t b = 0; b < count; ++b) {
        const double norm = std::sqrt(dq[b] * dq[b] + dp[b] * dp[b]);
        log_stretch[b] += std::log(norm);
        dq[b] /= norm;
        dp[b] /= norm;
      }
  }
}

}  // namespace bench
