#pragma once
// The tangent map of Tao's extended phase-space integrator (tao_extended_phase_space.hpp; M. Tao, Phys. Rev. E 94,
// 043303 (2016)): the exact derivative of the discrete map, the product of the tangents of its exact sub-flows on the
// extended phase space, applied to k tangent vectors per state alongside the step.
//
// A tangent vector of the extended space is w = (dq, dp, dx, dy). With hvp_H(point, direction) = (d(dH/dq),
// d(dH/dp)) (hamiltonian_gradient.hpp, ModelWithHamiltonianHessian; the plugin entry hvp_H):
//   phi_A(h): dp -= h d(dH/dq)(q, y)[dq, dy],   dx += h d(dH/dp)(q, y)[dq, dy]     ((q, y) and (dq, dy) fixed)
//   phi_B(h): dq += h d(dH/dp)(x, p)[dx, dp],   dy -= h d(dH/dq)(x, p)[dx, dp]     ((x, p) and (dx, dp) fixed)
//   phi_C:    the differences (dq - dx, dp - dy) turn as (q - x, p - y) do; the sums stay (a linear map)
// each at the point its flow left unchanged; TaoExtendedPhaseSpace's step observer (TaoFlow) hands them out, so the
// states get bit for bit the numbers of the plain scheme and the splitting is written once.
//
// Projection to (q, p). The run's map is z = (q, p) -> P Phi(E z) with the embedding E z = (q, p, q, p) at the start
// and the projection P (q, p, x, y) = (q, p): the tangent vectors the caller sees are P w, the (dq, dp) part. The
// copies' part (dx, dy) is this stepper's private state, initialised by E (dx = dq, dy = dp) at the first step, as
// the copies are. Between steps a caller may replace the vectors by linear combinations of themselves (Lyapunov
// renormalisation: V <- V C, lyapunov_exponents.hpp); the copies' part must follow with the same C. At each step the
// stepper compares the vectors with those its last step left: bit for bit equal, nothing to do; otherwise it recovers
// C by least squares from the old vectors (their QR factorisation by modified Gram-Schmidt, C = R^-1 Q^T V_new, exact
// for any C when the old vectors are independent) and applies it to the copies' part. A state whose old vectors are
// dependent (R_jj = 0), or which has none (before its first step, or restored from a checkpoint saved before it),
// starts its copies' part anew by E. The map on (q, p, x, y) is symplectic; its projection is not in general
// (nor is the scheme on (q, p)), so the spectrum of tao sums to zero only as the copies stay bound.
//
// Layout: tangent vectors as tangent_basic_step.hpp (vector j of state b at entry b*k + j); the copies' part the same
// (dx in q(), dy in p()), and the vectors the last step left beside it. Private state for a runner: save_state()
// adds them to the copies' columns ("tangent_copies_q", "tangent_copies_p", "tangent_last_q", "tangent_last_p",
// k*n per state), compact() and step_part() keep them aligned with the states as TaoExtendedPhaseSpace does.
//
// Cost: 4 hvp_H per vector per Strang step (phi_A and phi_B twice each), 3^(order/2 - 1) Strang steps per step.
// Errors: InvalidArgument for tangents that do not fit x or a model without hvp_H; the model's exceptions propagate
// (x, tangents and the private state are then unspecified).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/schemes/tao_extended_phase_space.hpp"
#include "nonsep/core/tangent/tangent_basic_step.hpp"

namespace nonsep {

class TangentTaoExtendedPhaseSpace {
 public:
  // `vectors_per_state`: k, for save_state() before the first step (0: known from the first step).
  explicit TangentTaoExtendedPhaseSpace(TaoExtendedPhaseSpace base = TaoExtendedPhaseSpace(),
                                        std::size_t vectors_per_state = 0)
      : base_(std::move(base)), k_(vectors_per_state) {}

  const TaoExtendedPhaseSpace& base() const { return base_; }
  HamiltonianForm form() const { return base_.form(); }
  const EvaluationCounts& evaluations() const { return base_.evaluations(); }
  const HessianCounts& hessian_evaluations() const { return hessians_; }

  // Advances x by dt as TaoExtendedPhaseSpace::step (with the copies it holds) and maps the tangent vectors.
  template <class M>
  requires ModelWithHamiltonianHessian<M>
  void step(const M& model, PhaseSpaceBatch& x, PhaseSpaceBatch& tangents, double dt) {
    k_ = check_tangents_fit(x, tangents);
    require_hamiltonian_hessian(model, "tao");
    if (hidden_.count() != tangents.count()) forget(tangents.dimension(), tangents.count());
    follow_renormalization(tangents);
    base_.step(model, x, dt, observer(model, tangents, hidden_));
    last_ = tangents;
  }

  // step_part of TaoExtendedPhaseSpace with the vectors: `part_tangents` hold the k vectors of states first ..
  // first + part.count() - 1 of a batch of `total` states, whose private state comes from `before`.
  template <class M>
  requires ModelWithHamiltonianHessian<M>
  void step_part(const M& model, PhaseSpaceBatch& part, PhaseSpaceBatch& part_tangents,
                 const TangentTaoExtendedPhaseSpace& before, std::size_t first, std::size_t total, double dt) {
    k_ = check_tangents_fit(part, part_tangents);
    require_hamiltonian_hessian(model, "tao");
    const std::size_t rows = part_tangents.count(), n = part.dimension();
    PhaseSpaceBatch hidden(n, rows), last(n, rows);
    std::fill(last.q().begin(), last.q().end(), std::numeric_limits<double>::quiet_NaN());
    if (before.hidden_.count() == total * k_) {
      copy_rows(before.hidden_, first * k_, hidden, 0, rows);
      copy_rows(before.last_, first * k_, last, 0, rows);
    }
    std::swap(hidden, hidden_);
    std::swap(last, last_);
    follow_renormalization(part_tangents);
    base_.step_part(model, part, before.base_, first, total, dt, observer(model, part_tangents, hidden_));
    last_ = part_tangents;
    std::swap(hidden, hidden_);
    std::swap(last, last_);
    if (hidden_.count() != total * k_) forget(n, total * k_);
    copy_rows(hidden, 0, hidden_, first * k_, rows);
    copy_rows(last, 0, last_, first * k_, rows);
  }

  void compact(const std::vector<bool>& retire) {
    base_.compact(retire);
    if (hidden_.count() != retire.size() * k_ || k_ == 0) return;
    std::size_t kept = 0;
    for (bool r : retire) kept += r ? 0 : 1;
    PhaseSpaceBatch hidden(hidden_.dimension(), kept * k_), last(hidden_.dimension(), kept * k_);
    for (std::size_t b = 0, slot = 0; b < retire.size(); ++b) {
      if (retire[b]) continue;
      copy_rows(hidden_, b * k_, hidden, slot * k_, k_);
      copy_rows(last_, b * k_, last, slot * k_, k_);
      ++slot;
    }
    hidden_ = std::move(hidden);
    last_ = std::move(last);
  }

  // The copies' columns of TaoExtendedPhaseSpace::save_state, then the four of the vectors (above); NaN for states
  // without them yet.
  SchemeState save_state(const PhaseSpaceBatch& states) const {
    SchemeState state = base_.save_state(states);
    const std::size_t per_state = k_ * states.dimension(), size = states.count() * per_state;
    const bool held = hidden_.count() * hidden_.dimension() == size && size > 0;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto column = [&](const char* name, std::span<const double> values) {
      state.columns.push_back(
          {name, per_state, held ? std::vector<double>(values.begin(), values.end()) : std::vector<double>(size, nan)});
    };
    column("tangent_copies_q", hidden_.q());
    column("tangent_copies_p", hidden_.p());
    column("tangent_last_q", last_.q());
    column("tangent_last_p", last_.p());
    return state;
  }
  void restore_state(const SchemeState& state) {
    if (state.columns.size() != 6) return;
    base_.restore_state(SchemeState{{state.columns[0], state.columns[1]}, state.largest});
    const std::size_t per_state = state.columns[2].per_state;
    if (per_state == 0 || k_ == 0 || state.columns[2].values.empty()) return;
    const std::size_t n = per_state / k_, rows = state.columns[2].values.size() / n;
    hidden_ = PhaseSpaceBatch(n, rows);
    last_ = PhaseSpaceBatch(n, rows);
    std::copy(state.columns[2].values.begin(), state.columns[2].values.end(), hidden_.q().begin());
    std::copy(state.columns[3].values.begin(), state.columns[3].values.end(), hidden_.p().begin());
    std::copy(state.columns[4].values.begin(), state.columns[4].values.end(), last_.q().begin());
    std::copy(state.columns[5].values.begin(), state.columns[5].values.end(), last_.p().begin());
  }
  std::vector<SchemeFigure> report() const { return base_.report(); }

  // The copies' part of the vectors (empty before the first step).
  const PhaseSpaceBatch& copy_tangents() const { return hidden_; }

 private:
  static void copy_rows(const PhaseSpaceBatch& from, std::size_t from_row, PhaseSpaceBatch& to, std::size_t to_row,
                        std::size_t rows) {
    const std::size_t n = from.dimension();
    std::copy_n(from.q().begin() + static_cast<std::ptrdiff_t>(from_row * n), rows * n,
                to.q().begin() + static_cast<std::ptrdiff_t>(to_row * n));
    std::copy_n(from.p().begin() + static_cast<std::ptrdiff_t>(from_row * n), rows * n,
                to.p().begin() + static_cast<std::ptrdiff_t>(to_row * n));
  }

  // No copies' part for `rows` vectors: the next step starts each state's anew.
  void forget(std::size_t n, std::size_t rows) {
    hidden_ = PhaseSpaceBatch(n, rows);
    last_ = PhaseSpaceBatch(n, rows);
    std::fill(last_.q().begin(), last_.q().end(), std::numeric_limits<double>::quiet_NaN());
  }

  // The copies' part follows what the caller did to the vectors since the last step (above).
  void follow_renormalization(const PhaseSpaceBatch& tangents) {
    const std::size_t n = tangents.dimension(), k = k_, count = tangents.count() / k;
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t first = b * k * n, size = k * n;
      const auto same = [&](std::span<const double> a, std::span<const double> c) {
        return std::equal(a.begin() + first, a.begin() + first + size, c.begin() + first);
      };
      if (same(tangents.q(), last_.q()) && same(tangents.p(), last_.p())) continue;
      if (!combine(tangents, b)) {  // E: the copies' part is the vectors themselves
        std::copy_n(tangents.q().begin() + first, size, hidden_.q().begin() + first);
        std::copy_n(tangents.p().begin() + first, size, hidden_.p().begin() + first);
      }
    }
  }

  // For state b: C with V_new = V_old C by least squares (V_old = Q R by modified Gram-Schmidt), applied to the
  // copies' part. False when the old vectors are missing (NaN) or dependent.
  bool combine(const PhaseSpaceBatch& tangents, std::size_t b) {
    const std::size_t n = tangents.dimension(), k = k_, m = 2 * n;
    q_.assign(k * m, 0.0);
    r_.assign(k * k, 0.0);
    const auto old_entry = [&](std::size_t j, std::size_t i) {
      const std::size_t at = (b * k + j) * n;
      return i < n ? last_.q()[at + i] : last_.p()[at + i - n];
    };
    const auto new_entry = [&](std::size_t j, std::size_t i) {
      const std::size_t at = (b * k + j) * n;
      return i < n ? tangents.q()[at + i] : tangents.p()[at + i - n];
    };
    for (std::size_t j = 0; j < k; ++j)
      for (std::size_t i = 0; i < m; ++i) q_[j * m + i] = old_entry(j, i);
    for (std::size_t j = 0; j < k; ++j) {
      for (std::size_t l = 0; l < j; ++l) {
        double dot = 0.0;
        for (std::size_t i = 0; i < m; ++i) dot += q_[l * m + i] * q_[j * m + i];
        r_[l * k + j] = dot;
        for (std::size_t i = 0; i < m; ++i) q_[j * m + i] -= dot * q_[l * m + i];
      }
      double norm = 0.0;
      for (std::size_t i = 0; i < m; ++i) norm += q_[j * m + i] * q_[j * m + i];
      norm = std::sqrt(norm);
      if (!(norm > 0.0) || !std::isfinite(norm)) return false;
      r_[j * k + j] = norm;
      for (std::size_t i = 0; i < m; ++i) q_[j * m + i] /= norm;
    }
    // C = R^-1 (Q^T V_new), column by column by back substitution.
    c_.assign(k * k, 0.0);
    for (std::size_t col = 0; col < k; ++col)
      for (std::size_t row = k; row-- > 0;) {
        double sum = 0.0;
        for (std::size_t i = 0; i < m; ++i) sum += q_[row * m + i] * new_entry(col, i);
        for (std::size_t l = row + 1; l < k; ++l) sum -= r_[row * k + l] * c_[l * k + col];
        c_[row * k + col] = sum / r_[row * k + row];
      }
    // hidden_new_j = sum_l hidden_old_l C_lj.
    combined_.assign(2 * k * n, 0.0);
    for (std::size_t j = 0; j < k; ++j)
      for (std::size_t l = 0; l < k; ++l)
        for (std::size_t i = 0; i < n; ++i) {
          combined_[j * n + i] += c_[l * k + j] * hidden_.q()[(b * k + l) * n + i];
          combined_[(k + j) * n + i] += c_[l * k + j] * hidden_.p()[(b * k + l) * n + i];
        }
    std::copy_n(combined_.begin(), k * n, hidden_.q().begin() + static_cast<std::ptrdiff_t>(b * k * n));
    std::copy_n(combined_.begin() + static_cast<std::ptrdiff_t>(k * n), k * n,
                hidden_.p().begin() + static_cast<std::ptrdiff_t>(b * k * n));
    return true;
  }

  // The step observer: the tangent of each sub-flow applied to (tangents, hidden), k rows per state.
  template <class M>
  auto observer(const M& model, PhaseSpaceBatch& tangents, PhaseSpaceBatch& hidden) {
    return [this, &model, &tangents, &hidden](const TaoFlow& flow, const PhaseSpaceBatch& x,
                                              const PhaseSpaceBatch& copies) {
      const std::size_t size = tangents.size();
      if (flow.kind == TaoFlow::Kind::C) {
        const double c = flow.cos, s = flow.sin;
        std::span<double> q = tangents.q(), p = tangents.p(), xq = hidden.q(), yp = hidden.p();
        for (std::size_t i = 0; i < size; ++i) {
          const double sum_q = q[i] + xq[i], sum_p = p[i] + yp[i], dq = q[i] - xq[i], dp = p[i] - yp[i];
          const double turned_q = c * dq + s * dp, turned_p = -s * dq + c * dp;
          q[i] = (sum_q + turned_q) / 2.0;
          xq[i] = (sum_q - turned_q) / 2.0;
          p[i] = (sum_p + turned_p) / 2.0;
          yp[i] = (sum_p - turned_p) / 2.0;
        }
        return;
      }
      // A: at (q, y) along (dq, dy), changing dp and dx; B: at (x, p) along (dx, dp), changing dq and dy.
      const bool a = flow.kind == TaoFlow::Kind::A;
      products(model, a ? x.q() : copies.q(), a ? copies.p() : x.p(), a ? tangents.q() : hidden.q(),
               a ? hidden.p() : tangents.p(), tangents.count() / x.count(), x.dimension());
      const double h = flow.h;
      std::span<double> minus = a ? tangents.p() : hidden.p(), plus = a ? hidden.q() : tangents.q();
      for (std::size_t i = 0; i < size; ++i) {
        minus[i] -= h * product_q_[i];
        plus[i] += h * product_p_[i];
      }
    };
  }

  // hvp_H at the points (q, p) of each state (repeated for its k rows) along the rows (dq, dp).
  template <class M>
  void products(const M& model, std::span<const double> q, std::span<const double> p, std::span<const double> dq,
                std::span<const double> dp, std::size_t k, std::size_t n) {
    const std::size_t rows = dq.size() / n;
    for (auto* v : {&point_q_, &point_p_, &product_q_, &product_p_}) v->resize(rows * n);
    for (std::size_t r = 0; r < rows; ++r) {
      std::copy_n(q.begin() + static_cast<std::ptrdiff_t>((r / k) * n), n,
                  point_q_.begin() + static_cast<std::ptrdiff_t>(r * n));
      std::copy_n(p.begin() + static_cast<std::ptrdiff_t>((r / k) * n), n,
                  point_p_.begin() + static_cast<std::ptrdiff_t>(r * n));
    }
    model.hvp_H(base_.form(), point_q_, point_p_, dq, dp, product_q_, product_p_, rows);
    hessians_.hvp_H += rows;
  }
  TaoExtendedPhaseSpace base_;
  std::size_t k_;
  HessianCounts hessians_;
  PhaseSpaceBatch hidden_, last_;  // the copies' part of the vectors, and the vectors as the last step left them
  std::vector<double> q_, r_, c_, combined_;
  std::vector<double> point_q_, point_p_, product_q_, product_p_;
};

// The tangent map of the stepper (BasicTangentIntegrator, tangent_integrator.hpp): its states stepped bit for bit
// as the stepper steps them; k vectors per state size the copies' part before the first step.
inline TangentTaoExtendedPhaseSpace tangent_map_of(const TaoExtendedPhaseSpace& stepper, std::size_t k) {
  return TangentTaoExtendedPhaseSpace(stepper, k);
}

}  // namespace nonsep
