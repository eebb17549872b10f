#pragma once
// Internal to the ensemble driver: the tangent vectors of one block's trajectories, for /analysis/lyapunov and
// /analysis/megno, /analysis/sali and /analysis/gali. When a run asks for them, the block steps with
// nonsep::TangentIntegrator instead of nonsep::Integrator: the states get the same numbers bit for bit
// (tangent_integrator.hpp), and k vectors per state follow the exact tangent map of each step. After every step
// LyapunovExponents::after_step takes the growth of the first vector (only for MEGNO) and re-orthonormalises every
// `renormalize_every` steps (lyapunov_exponents.hpp); MegnoRecord::add_step sums Y and <Y> (megno.hpp); with SALI or
// GALI each slot keeps the triangular factor of alignment_indices.hpp, updated at the orthonormalisations.
//
// Initial vectors (the same for every trajectory, fixed so that results are reproducible): vector 0 is
// w = (1, 1/2, 1/3, ..., 1/(2n)) over (dq_0 .. dq_(n-1), dp_0 .. dp_(n-1)), a generic direction (not along the flow
// or a torus of the shipped models), normalised; vector j >= 1 is the unit vector of component j, independent of
// w and of each other. LyapunovExponents::start orthonormalises them, keeping w's direction.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "nonsep/core/analysis/lyapunov_exponents.hpp"
#include "nonsep/core/analysis/megno.hpp"
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
  bool with_megno;                       // EnsembleSetup::megno
  PhaseSpaceBatch vectors;               // k per slot: vector j of slot s at entry s*k + j
  std::vector<LyapunovRecord> lyapunov;  // per slot
  std::vector<MegnoRecord> megno;        // per slot (zeros unless MEGNO is asked)
  std::vector<double> growth;            // scratch: ln-growth of vector 0 over the last step, per slot (MEGNO)
  std::size_t factor_size;               // numbers per slot in `alignment`; 0 without SALI and GALI
  std::vector<double> alignment;         // per slot: the factor of alignment_indices.hpp

  // setup.tangent_vectors per state, `slots` states.
  BlockTangents(const EnsembleSetup& setup, std::size_t slots)
      : integrator(setup.integrator, setup.tangent_vectors),
        exponents(setup.tangent_vectors, setup.renormalize_every),
        k(setup.tangent_vectors),
        with_megno(setup.megno),
        vectors(setup.dimension, slots * setup.tangent_vectors),
        lyapunov(slots),
        megno(slots),
        growth(setup.megno ? slots : 0),
        factor_size(setup.alignment_indices ? AlignmentIndices(k).factor_size() : 0),
        alignment(slots * factor_size) {}

  // Every slot at time 0: the initial vectors, orthonormalised, and zeroed sums.
  void start() {
    const std::size_t n = vectors.dimension();
    const PhaseSpaceBatch one = initial_tangent_vectors(n, k);
    for (std::size_t s = 0; s < lyapunov.size(); ++s) {
      std::copy(one.q().begin(), one.q().end(), vectors.q().begin() + static_cast<std::ptrdiff_t>(s * k * n));
      std::copy(one.p().begin(), one.p().end(), vectors.p().begin() + static_cast<std::ptrdiff_t>(s * k * n));
    }
    exponents.start(vectors, lyapunov);
    std::fill(megno.begin(), megno.end(), MegnoRecord{});
    if (factor_size > 0) AlignmentIndices(k).start(alignment);
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
    after_step(dt);
  }

  // `n` steps of every slot, n calls of step(). A Chin scheme with a plugin's tangent kernel takes them in runs that
  // end at the orthonormalisations (one step a run with MEGNO, whose growth is taken at every step), each run one
  // kernel call (bit for bit step()'s numbers with the baseline instruction set; the wider sets round as their kernels
  // do); otherwise step by step through the evaluation path.
  template <class M>
  void step_n(const M& model, PhaseSpaceBatch& x, double dt, std::uint64_t n) {
    while (n > 0) {
      const std::uint64_t run = with_megno ? 1 : std::min(n, exponents.steps_to_renormalization(lyapunov));
      if (!integrator.step_kernel_n(model, x, vectors, dt, run)) break;
      exponents.after_steps(vectors, lyapunov, dt, run, growth, alignment);
      if (with_megno) add_megno_step(megno, growth, dt);
      n -= run;
    }
    for (; n > 0; --n) step(model, x, dt);
  }

  // The Lyapunov and MEGNO sums and the SALI/GALI factors after a step of dt of every slot.
  void after_step(double dt) {
    exponents.after_step(vectors, lyapunov, dt, growth, alignment);
    if (with_megno) add_megno_step(megno, growth, dt);
  }
  // The factor of alignment_indices.hpp of `slot` (empty without SALI and GALI).
  std::span<const double> factor(std::size_t slot) const {
    return std::span<const double>(alignment).subspan(slot * factor_size, factor_size);
  }

  // Checkpoints (DriverState): appends every slot's vectors, sums and factors; restore() takes slot s from entry
  // entries[s] of such lists (the block's members among the active trajectories of a checkpoint).
  void save(DriverState& state) const {
    state.tangent_q.insert(state.tangent_q.end(), vectors.q().begin(), vectors.q().end());
    state.tangent_p.insert(state.tangent_p.end(), vectors.p().begin(), vectors.p().end());
    state.lyapunov.insert(state.lyapunov.end(), lyapunov.begin(), lyapunov.end());
    state.megno.insert(state.megno.end(), megno.begin(), megno.end());
    state.alignment.insert(state.alignment.end(), alignment.begin(), alignment.end());
  }
  void restore(std::span<const std::size_t> entries, const DriverState& state) {
    const std::span<const double> q = state.tangent_q, p = state.tangent_p;
    const std::span<const LyapunovRecord> l = state.lyapunov;
    const std::span<const MegnoRecord> m = state.megno;
    const std::size_t size = k * vectors.dimension();
    for (std::size_t slot = 0; slot < entries.size(); ++slot) {
      std::copy_n(q.begin() + static_cast<std::ptrdiff_t>(entries[slot] * size), size,
                  vectors.q().begin() + static_cast<std::ptrdiff_t>(slot * size));
      std::copy_n(p.begin() + static_cast<std::ptrdiff_t>(entries[slot] * size), size,
                  vectors.p().begin() + static_cast<std::ptrdiff_t>(slot * size));
      lyapunov[slot] = l[entries[slot]];
      megno[slot] = m[entries[slot]];
      std::copy_n(state.alignment.begin() + static_cast<std::ptrdiff_t>(entries[slot] * factor_size), factor_size,
                  alignment.begin() + static_cast<std::ptrdiff_t>(slot * factor_size));
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
        megno[kept] = megno[s];
        std::copy_n(alignment.begin() + static_cast<std::ptrdiff_t>(s * factor_size), factor_size,
                    alignment.begin() + static_cast<std::ptrdiff_t>(kept * factor_size));
      }
      ++kept;
    }
    if (kept == retire.size()) return;
    PhaseSpaceBatch next(n, kept * k);
    std::copy_n(vectors.q().begin(), kept * k * n, next.q().begin());
    std::copy_n(vectors.p().begin(), kept * k * n, next.p().begin());
    vectors = std::move(next);
    lyapunov.resize(kept);
    megno.resize(kept);
    growth.resize(with_megno ? kept : 0);
    alignment.resize(kept * factor_size);
  }
};

}  // namespace nonsep::host
