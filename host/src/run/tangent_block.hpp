#pragma once
// Internal to the ensemble driver: the tangent vectors of one block's trajectories and the states of the run's chaos
// indicators (nonsep/core/analysis/indicator.hpp: Lyapunov exponents, MEGNO, SALI and GALI, FLI, OFLI). When a run asks
// for them, the block steps with nonsep::TangentIntegrator instead of nonsep::Integrator: the states get the same
// numbers bit for bit (tangent_integrator.hpp), and k vectors per state follow the exact tangent map of each step.
// After every step LyapunovExponents::after_step takes the growth of the first vector (when an indicator needs it) and
// re-orthonormalises every `renormalize_every` steps (lyapunov_exponents.hpp); each indicator then updates its state
// of each slot (after_step, and after_orthonormalization at the orthonormalisations). An indicator that needs the
// first vector's share across the flow (OFLI) gets it from grad H at the states, at time 0 (start_across_flow, once
// the block's model is known) and after every step: a gradient evaluation of its own, outside the scheme's counts.
//
// Initial vectors (the same for every trajectory, fixed so that results are reproducible): vector 0 is
// w = (1, 1/2, 1/3, ..., 1/(2n)) over (dq_0 .. dq_(n-1), dp_0 .. dp_(n-1)), a generic direction (not along the flow
// or a torus of the shipped models), normalised; vector j >= 1 is the unit vector of component j, independent of
// w and of each other. LyapunovExponents::start orthonormalises them, keeping w's direction.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/base/hamiltonian_gradient.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"

namespace nonsep::host {

// The initial tangent vectors above, k for one state of dimension n, in the tangent layout (vector j at entry j).
inline PhaseSpaceBatch initial_tangent_vectors(std::size_t n, std::size_t k) {
  PhaseSpaceBatch v(n, k);
  for (std::size_t i = 0; i < 2 * n; ++i) (i < n ? v.q()[i] : v.p()[i - n]) = 1.0 / static_cast<double>(i + 1);
  for (std::size_t j = 1; j < k; ++j) (j < n ? v.q()[j * n + j] : v.p()[j * n + j - n]) = 1.0;
  return v;
}

struct BlockTangents {
  TangentIntegrator integrator;
  LyapunovExponents exponents;
  std::size_t k;
  const IndicatorList* indicators;          // EnsembleSetup::indicators
  bool with_growth;                         // an indicator needs the first vector's growth at every step
  bool with_factors;                        // an indicator needs the orthonormalisations' triangular factors
  bool with_flow;                           // an indicator needs the first vector's share across the flow
  PhaseSpaceBatch vectors;                  // k per slot: vector j of slot s at entry s*k + j
  std::vector<LyapunovRecord> lyapunov;     // per slot
  std::vector<std::vector<double>> states;  // per indicator: its state_size numbers per slot
  std::vector<double> growth;               // scratch: ln-growth of vector 0 over the last step, per slot
  std::vector<double> across;               // scratch: ln(|w_perp| / |w|) of vector 0 after the step, per slot
  HamiltonianGradient flow;                 // grad H at the states, for `across`
  std::vector<double> dH_dq, dH_dp;         // its output
  std::vector<IndicatorNeeds> needs;        // per indicator: Indicator::needs()
  std::vector<std::size_t> column_counts;   // per indicator: its number of columns

  // setup.tangent_vectors per state, `slots` states.
  BlockTangents(const EnsembleSetup& setup, std::size_t slots)
      : integrator(setup.integrator, setup.tangent_vectors),
        exponents(setup.tangent_vectors, setup.renormalize_every),
        k(setup.tangent_vectors),
        indicators(&setup.indicators),
        with_growth(std::any_of(setup.indicators.begin(), setup.indicators.end(),
                                [](const auto& i) { return i->needs().first_growth; })),
        with_factors(std::any_of(setup.indicators.begin(), setup.indicators.end(),
                                 [](const auto& i) { return i->needs().orthonormalization_factors; })),
        with_flow(std::any_of(setup.indicators.begin(), setup.indicators.end(),
                              [](const auto& i) { return i->needs().across_flow; })),
        vectors(setup.dimension, slots * setup.tangent_vectors),
        lyapunov(slots),
        growth(with_growth ? slots : 0),
        flow(setup.integrator.form) {
    for (const auto& indicator : setup.indicators) {
      needs.push_back(indicator->needs());
      states.emplace_back(slots * needs.back().state_size);
      column_counts.push_back(indicator->columns().size());
    }
  }

  std::size_t slots() const { return lyapunov.size(); }
  // Indicator i's state of `slot`.
  std::span<double> state(std::size_t i, std::size_t slot) {
    const std::size_t size = needs[i].state_size;
    return std::span<double>(states[i]).subspan(slot * size, size);
  }
  std::span<const double> state(std::size_t i, std::size_t slot) const {
    const std::size_t size = needs[i].state_size;
    return std::span<const double>(states[i]).subspan(slot * size, size);
  }

  // Every slot at time 0: the initial vectors, orthonormalised, and every indicator's start.
  void start() {
    const std::size_t n = vectors.dimension();
    const PhaseSpaceBatch one = initial_tangent_vectors(n, k);
    for (std::size_t s = 0; s < slots(); ++s) {
      std::copy(one.q().begin(), one.q().end(), vectors.q().begin() + static_cast<std::ptrdiff_t>(s * k * n));
      std::copy(one.p().begin(), one.p().end(), vectors.p().begin() + static_cast<std::ptrdiff_t>(s * k * n));
    }
    exponents.start(vectors, lyapunov);
    for (std::size_t i = 0; i < indicators->size(); ++i)
      for (std::size_t s = 0; s < slots(); ++s) (*indicators)[i]->start(state(i, s));
  }

  // At time 0, after start() and with the block's model: the first vector's share across the flow at the states of
  // x, for the indicators that need it (nothing without one). A model error propagates (grad H at the initial states
  // was checked when the job was loaded).
  template <class M>
  void start_across_flow(const M& model, const PhaseSpaceBatch& x) {
    if (!with_flow) return;
    measure_across_flow(model, x);
    for (std::size_t i = 0; i < indicators->size(); ++i)
      if (needs[i].across_flow)
        for (std::size_t s = 0; s < slots(); ++s) (*indicators)[i]->across_flow(state(i, s), across[s], true);
  }

  // Steps the states of `x`, which are slots first .. first + x.count() - 1 of the block, with their vectors and the
  // scheme's private state as they were in `before` (this block's tangents before the step); writes the mapped vectors
  // into `vectors`.
  template <class M>
  void step_part(const M& model, PhaseSpaceBatch& x, const BlockTangents& before, std::size_t first, double dt) {
    const std::size_t n = vectors.dimension(), size = x.count() * k * n;
    const auto offset = static_cast<std::ptrdiff_t>(first * k * n);
    PhaseSpaceBatch part(n, x.count() * k);
    std::copy_n(before.vectors.q().begin() + offset, size, part.q().begin());
    std::copy_n(before.vectors.p().begin() + offset, size, part.p().begin());
    integrator.step_part(model, x, part, before.integrator, first, before.vectors.count() / k, dt);
    std::copy(part.q().begin(), part.q().end(), vectors.q().begin() + offset);
    std::copy(part.p().begin(), part.p().end(), vectors.p().begin() + offset);
  }

  // A step of every slot at once.
  template <class M>
  void step(const M& model, PhaseSpaceBatch& x, double dt) {
    integrator.step(model, x, vectors, dt);
    if (with_flow) measure_across_flow(model, x);
    after_steps(dt, 1);
  }

  // `n` steps of every slot, n calls of step(). A Chin scheme with a plugin's tangent kernel takes them in runs that
  // end at the orthonormalisations (one step a run when an indicator takes the growth at every step), each run one
  // kernel call (bit for bit step()'s numbers with the baseline instruction set; the wider sets round as their kernels
  // do); otherwise step by step through the evaluation path.
  template <class M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    while (n > 0) {
      const std::uint64_t run = with_growth ? 1 : std::min(n, exponents.steps_to_renormalization(lyapunov));
      if (!integrator.step_kernel_n(model, x, vectors, dt, run)) break;
      if (with_flow) measure_across_flow(model, x);
      after_steps(dt, run);
      n -= run;
    }
    for (; n > 0; --n) step(model, x, dt);
  }

  // The Lyapunov sums and every indicator's state after a step of dt of every slot, now at the states of x (step_part
  // of every slot, some of which may have failed: the share across the flow is then measured state by state, NaN
  // where the model fails).
  template <class M>
  void after_step(const M& model, const PhaseSpaceBatch& x, double dt) {
    if (with_flow) {
      const std::size_t n = x.dimension();
      across.resize(slots());
      dH_dq.resize(slots() * n);
      dH_dp.resize(slots() * n);
      for (std::size_t s = 0; s < slots(); ++s) {
        try {
          flow.evaluate(model, x.q(s), x.p(s), std::span<double>(dH_dq).subspan(s * n, n),
                        std::span<double>(dH_dp).subspan(s * n, n), 1);
          across[s] = across_of(s);
        } catch (const ModelError&) {
          across[s] = std::numeric_limits<double>::quiet_NaN();
        }
      }
    }
    after_steps(dt, 1);
  }

  // The values of every indicator's columns of `slot`, in the list's order, appended to `values`.
  void values(std::size_t slot, std::vector<double>& values) const {
    for (std::size_t i = 0; i < indicators->size(); ++i) {
      const Indicator& indicator = *(*indicators)[i];
      const std::size_t first = values.size();
      values.resize(first + column_counts[i]);
      indicator.values(state(i, slot), lyapunov[slot], std::span<double>(values).subspan(first));
    }
  }

  // Checkpoints (DriverState, whose `indicators` are those of the run, named): appends every slot's vectors, sums and
  // indicator states; restore() takes slot s from entry entries[s] of such lists (the block's members among the
  // active trajectories of a checkpoint).
  void save(DriverState& state) const {
    state.tangent_q.insert(state.tangent_q.end(), vectors.q().begin(), vectors.q().end());
    state.tangent_p.insert(state.tangent_p.end(), vectors.p().begin(), vectors.p().end());
    state.lyapunov.insert(state.lyapunov.end(), lyapunov.begin(), lyapunov.end());
    for (std::size_t i = 0; i < states.size(); ++i)
      state.indicators[i].values.insert(state.indicators[i].values.end(), states[i].begin(), states[i].end());
  }
  void restore(std::span<const std::size_t> entries, const DriverState& saved) {
    const std::span<const double> q = saved.tangent_q, p = saved.tangent_p;
    const std::size_t size = k * vectors.dimension();
    for (std::size_t slot = 0; slot < entries.size(); ++slot) {
      std::copy_n(q.begin() + static_cast<std::ptrdiff_t>(entries[slot] * size), size,
                  vectors.q().begin() + static_cast<std::ptrdiff_t>(slot * size));
      std::copy_n(p.begin() + static_cast<std::ptrdiff_t>(entries[slot] * size), size,
                  vectors.p().begin() + static_cast<std::ptrdiff_t>(slot * size));
      lyapunov[slot] = saved.lyapunov[entries[slot]];
      for (std::size_t i = 0; i < states.size(); ++i) {
        const std::size_t n = needs[i].state_size;
        std::copy_n(saved.indicators[i].values.begin() + static_cast<std::ptrdiff_t>(entries[slot] * n), n,
                    state(i, slot).begin());
      }
    }
  }

  // Removes the slots marked in `retire`, keeping the others in order.
  void compact(const std::vector<bool>& retire) {
    integrator.compact(retire);
    const std::size_t n = vectors.dimension();
    std::size_t kept = 0;
    for (std::size_t s = 0; s < retire.size(); ++s) {
      if (retire[s]) continue;
      if (kept != s) {
        std::copy_n(vectors.q().begin() + static_cast<std::ptrdiff_t>(s * k * n), k * n,
                    vectors.q().begin() + static_cast<std::ptrdiff_t>(kept * k * n));
        std::copy_n(vectors.p().begin() + static_cast<std::ptrdiff_t>(s * k * n), k * n,
                    vectors.p().begin() + static_cast<std::ptrdiff_t>(kept * k * n));
        lyapunov[kept] = lyapunov[s];
        for (std::size_t i = 0; i < states.size(); ++i) {
          const auto from = state(i, s);
          std::copy(from.begin(), from.end(), state(i, kept).begin());
        }
      }
      ++kept;
    }
    if (kept == retire.size()) return;
    PhaseSpaceBatch next(n, kept * k);
    std::copy_n(vectors.q().begin(), kept * k * n, next.q().begin());
    std::copy_n(vectors.p().begin(), kept * k * n, next.p().begin());
    vectors = std::move(next);
    lyapunov.resize(kept);
    for (std::size_t i = 0; i < states.size(); ++i) states[i].resize(kept * needs[i].state_size);
    growth.resize(with_growth ? kept : 0);
  }

 private:
  // across[s] for every slot at the states of x, one batched gradient.
  template <class M>
  void measure_across_flow(const M& model, const PhaseSpaceBatch& x) {
    across.resize(slots());
    const std::size_t n = x.dimension(), size = slots() * n;
    dH_dq.resize(size);
    dH_dp.resize(size);
    flow.evaluate(model, x.q(), x.p(), dH_dq, dH_dp, slots());
    for (std::size_t s = 0; s < slots(); ++s) across[s] = across_of(s);
  }

  // ln(|w_perp| / |w|) of slot s's first vector w against the flow f = (dH/dp, -dH/dq) in dH_dq, dH_dp: w_perp is
  // formed (w - (w.f / f.f) f), not 1 - cos^2, so that a vector nearly along the flow keeps its digits.
  double across_of(std::size_t s) const {
    const std::size_t n = vectors.dimension();
    const double* wq = vectors.q().data() + s * k * n;
    const double* wp = vectors.p().data() + s * k * n;
    const double* gq = dH_dq.data() + s * n;
    const double* gp = dH_dp.data() + s * n;
    double wf = 0.0, ff = 0.0, ww = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      wf += wq[i] * gp[i] - wp[i] * gq[i];
      ff += gp[i] * gp[i] + gq[i] * gq[i];
      ww += wq[i] * wq[i] + wp[i] * wp[i];
    }
    if (!(ff > 0.0)) return 0.0;  // an equilibrium: no flow direction to remove
    const double c = wf / ff;
    double perp = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dq = wq[i] - c * gp[i], dp = wp[i] + c * gq[i];
      perp += dq * dq + dp * dp;
    }
    return 0.5 * std::log(perp / ww);
  }

  void after_steps(double dt, std::uint64_t steps) {
    LyapunovExponents::OrthonormalizationHook hook;
    if (with_factors)
      hook = [this](std::size_t slot, std::span<const double> r) {
        for (std::size_t i = 0; i < indicators->size(); ++i)
          if (needs[i].orthonormalization_factors) (*indicators)[i]->after_orthonormalization(state(i, slot), r, k);
      };
    exponents.after_steps(vectors, lyapunov, dt, steps, growth, hook);
    // Only indicators that take the growth have a per-step update; their runs are one step each (step_n).
    for (std::size_t i = 0; i < indicators->size(); ++i)
      if (needs[i].first_growth)
        for (std::size_t s = 0; s < slots(); ++s) (*indicators)[i]->after_step(state(i, s), growth[s], dt);
    if (with_flow)
      for (std::size_t i = 0; i < indicators->size(); ++i)
        if (needs[i].across_flow)
          for (std::size_t s = 0; s < slots(); ++s) (*indicators)[i]->across_flow(state(i, s), across[s], false);
  }
};

}  // namespace nonsep::host
