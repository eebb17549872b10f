#pragma once
// Tao's explicit symplectic integrator in an extended phase space, for any H (not only Chin's T_i V_ij T_j forms):
// M. Tao, "Explicit symplectic approximation of nonseparable Hamiltonians: algorithm and long time performance",
// Phys. Rev. E 94, 043303 (2016). Two copies (q, p) and (x, y) of phase space are bound together by
//
//   Hbar(q, p, x, y) = H_A + H_B + omega H_C,   H_A = H(q, y),   H_B = H(x, p),   H_C = (|q - x|^2 + |p - y|^2) / 2,
//
// and each part has an exact flow (H the solved H_TTV or H_VVT, its gradient from hamiltonian_gradient.hpp):
//   phi_A(d): p -= d dH/dq(q, y),   x += d dH/dp(q, y)          (q, y fixed)
//   phi_B(d): q += d dH/dp(x, p),   y -= d dH/dq(x, p)          (x, p fixed)
//   phi_C(d): the differences (q - x, p - y) turn by the angle 2 omega d, the sums (q + x, p + y) stay:
//     q = (q + x + c (q - x) + s (p - y)) / 2,   p = (p + y - s (q - x) + c (p - y)) / 2,
//     x = (q + x - c (q - x) - s (p - y)) / 2,   y = (p + y + s (q - x) - c (p - y)) / 2,   c, s = cos, sin(2 omega d).
// The order-2 step is Tao's Strang splitting  phi_A(dt/2) phi_B(dt/2) phi_C(dt) phi_B(dt/2) phi_A(dt/2);
// orders 4 and 6 compose it by Yoshida's triple jump, Phi_{2k+2}(dt) = Phi_2k(g dt) Phi_2k(-r g dt) Phi_2k(g dt),
// r = 2^(1/(2k+1)), g = 1/(2 - r), the construction of Tao's higher orders (H. Yoshida, Phys. Lett. A 150, 262 (1990)).
//
// On the diagonal q = x, p = y the exact flow of Hbar is that of H on each copy, so (q, p) approximates the flow of H
// with the scheme's order. The map is symplectic on the extended phase space (dq^dp + dx^dy) and symmetric (the
// step of -dt undoes the step of dt, on (q, p, x, y)); the projection to (q, p) is neither in general.
// Tao's error bound is O(T dt^l omega) for an order-l scheme, valid when dt << omega^(-1/l); omega must also be
// large against the rate at which the copies drift apart (about the frequencies of the dynamics). The default
// omega = 20 is the value of Tao's examples. Measured on paper1d (frequencies O(1), tests/core): the orders are
// asymptotic for dt <= T/64 = 0.006 (omega dt <= 0.12) and still converging at dt = 0.05 (omega dt = 1).
//
// Cost: phi_A needs the gradient of H at (q, y), phi_B at (x, p). phi_A leaves (q, y) unchanged, so the gradient of a
// Strang step's last phi_A serves the next phi_A (of the next Strang step, or of the next step when the state still
// holds that point bit for bit): 3 grad H per Strang step, 3^(order/2) per step, plus one at the start.
//
// The extra copy (x, y) is part of each trajectory's state. Layout: a PhaseSpaceBatch of the same shape as the
// states, x in its q(), y in its p() (state b at b*n + i). Either the caller holds it and passes it to
// step(model, x, copies, dt), or the stepper holds it (step(model, x, dt)): then an empty copy batch is initialised
// to (q, p) by the next step, and the host must keep it aligned with the states: compact_copies() when it retires
// states, copy_of() / restore_copies() to save, redo a single state or restore from a checkpoint.
// copy_distance() reports |(q, p) - (x, y)| per state: small (compared with the state) while the binding holds.
// For a runner that holds the copies in the stepper (nonsep::Integrator): step_part(), compact(), save_state() and
// restore_state() (scheme_state.hpp) keep them aligned with the states without the runner knowing of them, and the
// stepper tracks the largest copy distance of its steps (report()).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/base/scheme_state.hpp"
#include "nonsep/core/schemes/chin_basic_step.hpp"
#include "nonsep/core/schemes/comparator_description.hpp"

namespace nonsep {

// One exact sub-flow of the Strang step, as a step's observer sees it (tangent_tao_extended_phase_space.hpp), called
// after the flow with the states and copies as it left them: phi_A and phi_B of time h (their points (q, y) and
// (x, p), which they leave unchanged), phi_C of its turn by the angle 2 omega dt (cos, sin).
struct TaoFlow {
  enum class Kind { A, B, C };
  Kind kind = Kind::A;
  double h = 0.0;
  double cos = 1.0, sin = 0.0;
};
struct NoTaoObserver {
  void operator()(const TaoFlow&, const PhaseSpaceBatch&, const PhaseSpaceBatch&) const {}
};

class TaoExtendedPhaseSpace {
 public:
  static constexpr double default_omega = 20.0;

  // Throws InvalidArgument unless order is 2, 4 or 6 and omega is finite and positive.
  explicit TaoExtendedPhaseSpace(HamiltonianForm form = HamiltonianForm::TTV, int order = 2,
                                 double omega = default_omega)
      : gradient_(form), order_(order), omega_(omega) {
    check(order, omega);
  }
  // Throws InvalidArgument unless order is 2, 4 or 6 and omega is finite and positive.
  static void check(int order, double omega) {
    if (order != 2 && order != 4 && order != 6)
      throw InvalidArgument("Tao's extended phase-space integrator has orders 2, 4 and 6 (found " +
                            std::to_string(order) + ")");
    if (!std::isfinite(omega) || omega <= 0.0)
      throw InvalidArgument("the binding omega must be finite and positive; the default is 20 (found " +
                            found_number(omega) + ")");
  }

  HamiltonianForm form() const { return gradient_.form(); }
  int order() const { return order_; }
  double omega() const { return omega_; }
  const EvaluationCounts& evaluations() const { return gradient_.evaluations(); }
  void add_evaluations(const EvaluationCounts& counts) { gradient_.add_evaluations(counts); }

  ComparatorDescription describe() const { return description(order_, omega_); }
  // The description of the integrator of this order and omega (its scheme's, comparator_schemes.hpp, without
  // building one).
  static ComparatorDescription description(int order, double omega) {
    const int strang = order == 2 ? 1 : order == 4 ? 3 : 9;
    ComparatorDescription d;
    d.scheme = "tao";
    d.method = "Tao's explicit symplectic integrator in extended phase space";
    d.reference = "M. Tao, Phys. Rev. E 94, 043303 (2016); triple jump: H. Yoshida, Phys. Lett. A 150, 262 (1990)";
    d.order = order;
    d.properties = "symplectic and symmetric on the extended phase space (q, p, x, y), not on (q, p) alone";
    d.grad_H_per_step = static_cast<std::uint64_t>(3 * strang);
    d.cost = std::to_string(3 * strang) + " grad H per state per step (" + std::to_string(strang) + " Strang step" +
             (strang > 1 ? "s" : "") + " of 3), plus 1 at the start of a run";
    d.parameters = {{"omega", omega}};
    return d;
  }

  // Advances every state of x, and its copy, by dt (finite, non-zero). Throws InvalidArgument on a bad dt, a
  // batch whose dimension differs from the model's or copies of another shape than x; propagates the model's
  // exceptions (x and copies are then unspecified).
  // With an observer: observer(const TaoFlow&, const PhaseSpaceBatch& x, const PhaseSpaceBatch& copies) after each
  // sub-flow, in order.
  template <HamiltonianModel M, class Observer = NoTaoObserver>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& copies, double dt, Observer&& observer = {}) {
    check_step_size(dt);
    check_batch_fits(model, x);
    if (copies.dimension() != x.dimension() || copies.count() != x.count())
      throw InvalidArgument("the extended copies hold " + std::to_string(copies.count()) + " states of dimension " +
                            std::to_string(copies.dimension()) + " for a batch of " + std::to_string(x.count()) +
                            " states of dimension " + std::to_string(x.dimension()));
    compose(order_ / 2 - 1, model, x, copies, dt, observer);
  }

  // The same with the copies held by the stepper (initialised to x when empty); tracks the largest copy distance.
  template <HamiltonianModel M, class Observer = NoTaoObserver>
  void step(const M& model, PhaseSpaceBatch& x, double dt, Observer&& observer = {}) {
    if (copies_.count() == 0) copies_ = x;
    step(model, x, copies_, dt, observer);
    track_copy_distance(x, copies_);
  }

  // Redoes one step for part of the batch the stepper holds copies of: `part` holds states first ..
  // first + part.count() - 1 of a batch of `total` states whose step `before` (this stepper as it was before the
  // step) was to take. Their copies come from `before` (from the states when it held none yet) and are written
  // back into this stepper's copies.
  template <HamiltonianModel M, class Observer = NoTaoObserver>
  void step_part(const M& model, PhaseSpaceBatch& part, const TaoExtendedPhaseSpace& before, std::size_t first,
                 std::size_t total, double dt, Observer&& observer = {}) {
    PhaseSpaceBatch copies = before.copies_.count() == total ? slice(before.copies_, first, part.count()) : part;
    step(model, part, copies, dt, observer);
    PhaseSpaceBatch all = copies_.count() == total ? copies_ : PhaseSpaceBatch(part.dimension(), total);
    for (std::size_t b = 0; b < part.count(); ++b) {
      std::copy(copies.q(b).begin(), copies.q(b).end(), all.q(first + b).begin());
      std::copy(copies.p(b).begin(), copies.p(b).end(), all.p(first + b).begin());
    }
    copies_ = std::move(all);
    track_copy_distance(part, copies);
  }

  // compact_copies(), or nothing before the first step (no copies held yet).
  void compact(const std::vector<bool>& retire) {
    if (copies_.count() == retire.size()) compact_copies(retire);
  }

  // The copies of `states` (the batch the stepper steps; before its first step the copies are the states, as the
  // step would set them): columns "copies_q" (x) and "copies_p" (y), n numbers per state; and the largest copy
  // distance so far, "max_copy_distance".
  SchemeState save_state(const PhaseSpaceBatch& states) const {
    const PhaseSpaceBatch& held = copies_.count() == states.count() && copies_.count() > 0 ? copies_ : states;
    const std::size_t n = states.dimension();
    return {{{"copies_q", n, {held.q().begin(), held.q().end()}}, {"copies_p", n, {held.p().begin(), held.p().end()}}},
            {{"max_copy_distance", max_copy_distance_}}};
  }
  // Continues from save_state's copies (nothing when it has none), so that the run goes on as if never stopped.
  void restore_state(const SchemeState& state) {
    if (state.columns.size() != 2 || state.columns[0].values.empty() || state.columns[0].per_state == 0) return;
    const std::size_t n = state.columns[0].per_state;
    PhaseSpaceBatch copies(n, state.columns[0].values.size() / n);
    std::copy_n(state.columns[0].values.begin(), copies.size(), copies.q().begin());
    std::copy_n(state.columns[1].values.begin(), copies.size(), copies.p().begin());
    copies_ = std::move(copies);
    if (!state.largest.empty()) max_copy_distance_ = state.largest[0].value;
  }
  // For a run's summary: omega and the largest |(q, p) - (x, y)| of the steps this stepper took with its own copies.
  std::vector<SchemeFigure> report() const {
    return {{"omega", omega_, ""},
            {"max_copy_distance", max_copy_distance_,
             "largest |(q, p) - (x, y)| over the trajectories and steps of this process (a resumed run counts from "
             "the resume)"}};
  }

  // The copies held by the stepper (empty before the first step and after reset_copies()).
  const PhaseSpaceBatch& copies() const { return copies_; }
  // The copy of state b alone.
  PhaseSpaceBatch copy_of(std::size_t b) const { return PhaseSpaceBatch::single(copies_.q(b), copies_.p(b)); }
  void restore_copies(PhaseSpaceBatch copies) { copies_ = std::move(copies); }
  // Forgets the copies: the next step starts them from its states (a fresh start, not a continuation).
  void reset_copies() { copies_ = PhaseSpaceBatch(); }
  // Drops the copies of the states with retire[b] true and keeps the others in order, as the host compacts a
  // batch. Throws InvalidArgument when retire has not one entry per copy.
  void compact_copies(const std::vector<bool>& retire) {
    if (retire.size() != copies_.count())
      throw InvalidArgument("compacting " + std::to_string(copies_.count()) +
                            " extended copies needs as many flags (found " + std::to_string(retire.size()) + ")");
    std::size_t kept = 0;
    for (bool r : retire) kept += r ? 0 : 1;
    if (kept == 0) {
      reset_copies();
      return;
    }
    PhaseSpaceBatch compacted(copies_.dimension(), kept);
    for (std::size_t b = 0, slot = 0; b < retire.size(); ++b) {
      if (retire[b]) continue;
      std::copy(copies_.q(b).begin(), copies_.q(b).end(), compacted.q(slot).begin());
      std::copy(copies_.p(b).begin(), copies_.p(b).end(), compacted.p(slot).begin());
      ++slot;
    }
    copies_ = std::move(compacted);
  }

  // |(q, p) - (x, y)| (Euclidean, over the 2n components) of each state into distance (size x.count()).
  static void copy_distance(const PhaseSpaceBatch& x, const PhaseSpaceBatch& copies, std::span<double> distance) {
    if (copies.dimension() != x.dimension() || copies.count() != x.count() || distance.size() != x.count())
      throw InvalidArgument("copy distance: " + std::to_string(x.count()) + " states need as many copies and outputs");
    const std::size_t n = x.dimension();
    for (std::size_t b = 0; b < x.count(); ++b) {
      double sum = 0.0;
      for (std::size_t i = b * n; i < (b + 1) * n; ++i) {
        sum += (x.q()[i] - copies.q()[i]) * (x.q()[i] - copies.q()[i]);
        sum += (x.p()[i] - copies.p()[i]) * (x.p()[i] - copies.p()[i]);
      }
      distance[b] = std::sqrt(sum);
    }
  }
  void copy_distance(const PhaseSpaceBatch& x, std::span<double> distance) const {
    copy_distance(x, copies_, distance);
  }

 private:
  static PhaseSpaceBatch slice(const PhaseSpaceBatch& x, std::size_t first, std::size_t count) {
    PhaseSpaceBatch out(x.dimension(), count);
    for (std::size_t b = 0; b < count; ++b) {
      std::copy(x.q(first + b).begin(), x.q(first + b).end(), out.q(b).begin());
      std::copy(x.p(first + b).begin(), x.p(first + b).end(), out.p(b).begin());
    }
    return out;
  }
  void track_copy_distance(const PhaseSpaceBatch& x, const PhaseSpaceBatch& copies) {
    distances_.resize(x.count());
    copy_distance(x, copies, distances_);
    for (double d : distances_) max_copy_distance_ = std::max(max_copy_distance_, d);
  }

  template <HamiltonianModel M, class Observer>
  void compose(int level, const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& copies, double dt, Observer& observer) {
    if (level == 0) {
      strang(model, x, copies, dt, observer);
      return;
    }
    const double r = std::pow(2.0, 1.0 / (2.0 * level + 1.0));
    const double outer = dt / (2.0 - r);
    compose(level - 1, model, x, copies, outer, observer);
    compose(level - 1, model, x, copies, -r * outer, observer);
    compose(level - 1, model, x, copies, outer, observer);
  }

  // phi_A(dt/2) phi_B(dt/2) phi_C(dt) phi_B(dt/2) phi_A(dt/2).
  template <HamiltonianModel M, class Observer>
  void strang(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& copies, double dt, Observer& observer) {
    const std::size_t size = x.size();
    const double h = dt / 2.0;
    std::span<double> q = x.q(), p = x.p(), xq = copies.q(), yp = copies.p();
    at_b_dq_.resize(size);
    at_b_dp_.resize(size);
    // phi_A: p -= h dH/dq(q, y), x += h dH/dp(q, y), from the gradient at (q, y) (cached when it is at hand).
    auto flow_a = [&] {
      for (std::size_t i = 0; i < size; ++i) {
        p[i] -= h * at_a_dq_[i];
        xq[i] += h * at_a_dp_[i];
      }
    };
    auto flow_b = [&] {
      gradient_.evaluate(model, xq, p, at_b_dq_, at_b_dp_, x.count());
      for (std::size_t i = 0; i < size; ++i) {
        q[i] += h * at_b_dp_[i];
        yp[i] -= h * at_b_dq_[i];
      }
    };
    if (!cached_at(q, yp)) evaluate_at_a(model, q, yp, x.count());
    flow_a();
    observer(TaoFlow{TaoFlow::Kind::A, h}, std::as_const(x), std::as_const(copies));
    flow_b();
    observer(TaoFlow{TaoFlow::Kind::B, h}, std::as_const(x), std::as_const(copies));
    const double c = std::cos(2.0 * omega_ * dt), s = std::sin(2.0 * omega_ * dt);
    for (std::size_t i = 0; i < size; ++i) {
      const double sum_q = q[i] + xq[i], sum_p = p[i] + yp[i], dq = q[i] - xq[i], dp = p[i] - yp[i];
      const double turned_q = c * dq + s * dp, turned_p = -s * dq + c * dp;
      q[i] = (sum_q + turned_q) / 2.0;
      xq[i] = (sum_q - turned_q) / 2.0;
      p[i] = (sum_p + turned_p) / 2.0;
      yp[i] = (sum_p - turned_p) / 2.0;
    }
    observer(TaoFlow{TaoFlow::Kind::C, dt, c, s}, std::as_const(x), std::as_const(copies));
    flow_b();
    observer(TaoFlow{TaoFlow::Kind::B, h}, std::as_const(x), std::as_const(copies));
    evaluate_at_a(model, q, yp, x.count());
    flow_a();
    observer(TaoFlow{TaoFlow::Kind::A, h}, std::as_const(x), std::as_const(copies));
  }

  bool cached_at(std::span<const double> q, std::span<const double> y) const {
    return cached_q_.size() == q.size() && cached_y_.size() == y.size() &&
           std::memcmp(cached_q_.data(), q.data(), q.size() * sizeof(double)) == 0 &&
           std::memcmp(cached_y_.data(), y.data(), y.size() * sizeof(double)) == 0;
  }

  template <HamiltonianModel M>
  void evaluate_at_a(const M& model, std::span<const double> q, std::span<const double> y, std::size_t count) {
    at_a_dq_.resize(q.size());
    at_a_dp_.resize(q.size());
    cached_q_.clear();  // invalid until the evaluation has succeeded
    gradient_.evaluate(model, q, y, at_a_dq_, at_a_dp_, count);
    cached_q_.assign(q.begin(), q.end());
    cached_y_.assign(y.begin(), y.end());
  }

  HamiltonianGradient gradient_;
  int order_;
  double omega_;
  PhaseSpaceBatch copies_;                 // (x, y) of each state when the stepper holds them
  std::vector<double> at_a_dq_, at_a_dp_;  // grad H at (q, y), the point the cache names
  std::vector<double> cached_q_, cached_y_;
  std::vector<double> at_b_dq_, at_b_dp_;  // grad H at (x, p)
  double max_copy_distance_ = 0.0;         // over the steps with the stepper's copies
  std::vector<double> distances_;
};

}  // namespace nonsep
