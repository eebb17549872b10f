#pragma once
// The model interface of the core: what an integrator needs to know about T(p) and V(q).
//
// Batch layout (used everywhere in nonsep, including the plugin ABI): a batch holds `count` states of
// dimension n, stored state-major and contiguous. Component i of state b is at index b*n + i, so each
// state's n numbers are adjacent. A gradient batch has the same layout as its input. A Hessian batch holds
// count row-major n x n matrices: entry (i, j) of state b is at index b*n*n + i*n + j.
//
// A type M models nonsep::Model when, for `const M m`, spans `x` (size count*n, read) and `out` (size count*n,
// written):
//   m.dimension()               -> std::size_t, the number of degrees of freedom n (> 0)
//   m.grad_T(x, out, count)     writes dT/dp_i evaluated at each of the count momenta in x
//   m.grad_V(x, out, count)     writes dV/dq_i evaluated at each of the count positions in x
// and nonsep::ModelWithHessians when moreover (out of size count*n*n):
//   m.hessian_T(x, out, count)  writes d2T/dp_i dp_j
//   m.hessian_V(x, out, count)  writes d2V/dq_i dq_j
// Hessians are needed only for the energy of the solved Hamiltonian, never for stepping.
//
// Evaluations may throw nonsep::ModelError (or anything else); integrators let it propagate and leave the
// state they were stepping unspecified but valid.
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <span>

namespace nonsep {

template <class M>
concept Model = requires(const M& m, std::span<const double> x, std::span<double> out, std::size_t count) {
  { m.dimension() } -> std::convertible_to<std::size_t>;
  m.grad_T(x, out, count);
  m.grad_V(x, out, count);
};

template <class M>
concept ModelWithHessians = Model<M> &&
    requires(const M& m, std::span<const double> x, std::span<double> out, std::size_t count) {
  m.hessian_T(x, out, count);
  m.hessian_V(x, out, count);
};

// and nonsep::ModelWithThirdDerivatives when moreover (u of size count*n, read; out of size count*n, written):
//   m.d3T(p, u, out, count)     writes sum_ij d3T/dp_i dp_j dp_k u_i u_j, k = 0..n-1, at each of the count momenta
//   m.d3V(q, u, out, count)     writes sum_ij d3V/dq_i dq_j dq_k u_i u_j, k = 0..n-1, at each of the count positions
template <class M>
concept ModelWithThirdDerivatives = ModelWithHessians<M> &&
    requires(const M& m, std::span<const double> x, std::span<const double> u, std::span<double> out,
             std::size_t count) {
  m.d3T(x, u, out, count);
  m.d3V(x, u, out, count);
};

// A model given by H(q, p) itself, of any shape (a charged particle in a magnetic field, a geodesic, ...), instead
// of the product form above. A type M models nonsep::ModelWithGeneralHamiltonian when, for `const M m`, spans q, p
// (size count*n, read), out (size count, written) and dH_dq, dH_dp (size count*n, written):
//   m.dimension()                        -> std::size_t, n
//   m.value_H(q, p, out, count)          writes H of each of the count states (q_b, p_b)
//   m.grad_H(q, p, dH_dq, dH_dp, count)  writes dH/dq_i and dH/dp_i at each state
// and, for the tangent maps, the directional derivative of grad H, hvp_H (hamiltonian_gradient.hpp), whose
// HamiltonianForm argument such a model ignores. A type that serves both kinds of model (a plugin) has
// `bool general_hamiltonian() const`, which says which kind this object is. The schemes that integrate H itself
// (Gauss-Legendre, Tao's extended phase space) and the energy take either kind (HamiltonianModel below); Chin's
// schemes split T(p) and V(q) and need the product form.
template <class M>
concept ModelWithGeneralHamiltonian = requires(const M& m, std::span<const double> x, std::span<double> out,
                                               std::size_t count) {
  { m.dimension() } -> std::convertible_to<std::size_t>;
  m.value_H(x, x, out, count);
  m.grad_H(x, x, out, out, count);
};

// Whether `model` is given by H itself (its type has the concept and, where it says, the object is of that kind).
template <class M>
bool is_general_hamiltonian(const M& model) {
  if constexpr (!ModelWithGeneralHamiltonian<M>)
    return false;
  else if constexpr (requires {
                       { model.general_hamiltonian() } -> std::convertible_to<bool>;
                     })
    return static_cast<bool>(model.general_hamiltonian());
  else
    return true;
}

// The models of the schemes that integrate H itself: the product form with its third derivatives (the gradient of
// H_TTV reaches them), or H itself.
template <class M>
concept HamiltonianModel = ModelWithThirdDerivatives<M> || ModelWithGeneralHamiltonian<M>;

// The optional separable part. A model may add K(p) + U(q) to the product form, so that the solved Hamiltonian is
//   H = T_i V_ij T_j + K(p) + U(q)   (TTV)      H = V_i T_ij V_j + K(p) + U(q)   (VVT)
// (separable_composition.hpp integrates it). M models nonsep::ModelWithSeparablePart when moreover
// (x, out as above; Hessians in the Hessian layout, values one number per state):
//   m.has_K(), m.has_U()        -> bool, whether this model has K (resp. U); a model without one of them has it zero
//                                  and is never asked for it. Constant for the model's lifetime.
//   m.grad_K(p, out, count)     writes dK/dp_i            m.grad_U(q, out, count)     writes dU/dq_i
//   m.value_K(p, out, count)    writes K (one per state)  m.value_U(q, out, count)    writes U (one per state)
//   m.hessian_K(p, out, count)  writes d2K/dp_i dp_j      m.hessian_U(q, out, count)  writes d2U/dq_i dq_j
// Whether a model has a separable part is known at compile time (the concept) and at run time (has_K, has_U: one
// plugin type serves models with and without). Stepping needs the gradients, the energy the values, the tangent
// map and the comparators' grad H the Hessians and gradients. A model without the concept, or with has_K() and
// has_U() false, is the pure product form and every integrator gives it bit for bit the numbers it gives it alone.
template <class M>
concept ModelWithSeparablePart = Model<M> &&
    requires(const M& m, std::span<const double> x, std::span<double> out, std::size_t count) {
  { m.has_K() } -> std::convertible_to<bool>;
  { m.has_U() } -> std::convertible_to<bool>;
  m.grad_K(x, out, count);
  m.grad_U(x, out, count);
  m.value_K(x, out, count);
  m.value_U(x, out, count);
  m.hessian_K(x, out, count);
  m.hessian_U(x, out, count);
};

// Whether `model` has K(p) (resp. U(q)): false for every model without the separable concept.
template <class M>
bool has_K(const M& model) {
  if constexpr (ModelWithSeparablePart<M>)
    return static_cast<bool>(model.has_K());
  else
    return false;
}
template <class M>
bool has_U(const M& model) {
  if constexpr (ModelWithSeparablePart<M>)
    return static_cast<bool>(model.has_U());
  else
    return false;
}
template <class M>
bool has_separable_part(const M& model) {
  return has_K(model) || has_U(model);
}

// Gradient evaluations performed by an integrator, counted per state: one batched call on `count` states
// counts `count` evaluations. grad_H counts evaluations of the full gradient (dH/dq, dH/dp) of the solved
// Hamiltonian by the comparator schemes (hamiltonian_gradient.hpp), each one gradient, two Hessians and one
// third-derivative contraction of the model; those model calls are not counted again in grad_T and grad_V.
struct EvaluationCounts {
  std::uint64_t grad_T = 0;
  std::uint64_t grad_V = 0;
  std::uint64_t grad_H = 0;
  std::uint64_t grad_K = 0;  // the separable part's flows (separable_composition.hpp)
  std::uint64_t grad_U = 0;

  EvaluationCounts& operator+=(const EvaluationCounts& other) {
    grad_T += other.grad_T;
    grad_V += other.grad_V;
    grad_H += other.grad_H;
    grad_K += other.grad_K;
    grad_U += other.grad_U;
    return *this;
  }
  friend bool operator==(const EvaluationCounts&, const EvaluationCounts&) = default;
};

// Which non-separable Hamiltonian the 9-stage splitting of T(p) + V(q) solves (paper, section III):
//   TTV: H = T_i(p) V_ij(q) T_j(p)   (kicks with grad V, drifts with grad T)
//   VVT: H = V_i(q) T_ij(p) V_j(q)   (roles of T and V interchanged, coefficients kept)
enum class HamiltonianForm { TTV, VVT };

}  // namespace nonsep
