#pragma once
// A model given by H(q, p) itself, of any shape, and HamiltonianAdapter, which turns one into a batched core model
// (nonsep::ModelWithGeneralHamiltonian, nonsep/core/base/model.hpp) with its derivatives by automatic
// differentiation or by the author's own code. Such a model is served by the schemes that integrate H itself
// (gauss, implicit_midpoint, tao) and every analysis; Chin's schemes need the product form (model_adapter.hpp).
//
// A Hamiltonian model class M (see plugins/henon_heiles/henon_heiles.hpp for a complete one) has
//   template <class S> S H(nonsep::sdk::Vector<S> q, nonsep::sdk::Vector<S> p) const;
// written once for any scalar S (double and the dual numbers of dual.hpp), its dimension (a fixed
// `static constexpr std::size_t dimension`, or max_dimension with dimension_parameter) and optionally parameters
// and a constructor from them, exactly as a product-form model (model_adapter.hpp). Optionally, hand-written:
//   void grad_H(Vector<double> q, Vector<double> p, std::span<double> dH_dq, std::span<double> dH_dp) const;
//   void hvp_H(Vector<double> q, Vector<double> p, Vector<double> dq, Vector<double> dp, std::span<double> out_q,
//              std::span<double> out_p) const;     the Hessian of H times (dq, dp), n numbers each
// each replacing automatic differentiation for it. Export it with NONSEP_EXPORT_HAMILTONIAN (plugin_sdk.hpp).
//
// Automatic differentiation runs over z = (q, p), 2n variables: the gradient in one pass of Dual<double, 2K>
// (gradient_by_dual), the directional derivative of grad H in one pass of Dual<Dual<double, 2K>, 1>
// (hessian_vector_by_dual), K the dimension or max_dimension; all on the stack, as model_adapter.hpp's. Non-finite
// values are numbers (the host reports the state as diverged); the products where H is not finite are NaN.
#include <algorithm>
#include <array>
#include <concepts>
#include <cstddef>
#include <span>
#include <string>

#include "nonsep/core/base/model.hpp"
#include "nonsep/sdk/automatic_derivatives.hpp"
#include "nonsep/sdk/model_adapter.hpp"

namespace nonsep::sdk {

template <class M>
concept HamiltonianClass = (HasFixedDimension<M> != HasParameterDimension<M>)&&(dimension_capacity<M>() > 0) &&
                           requires(const M& m, Vector<double> x, Vector<GradientDual<2 * dimension_capacity<M>()>> d,
                                    Vector<HessianDual<2 * dimension_capacity<M>()>> dd) {
  { m.template H<double>(x, x) } -> std::convertible_to<double>;
  m.template H<GradientDual<2 * dimension_capacity<M>()>>(d, d);
  m.template H<HessianDual<2 * dimension_capacity<M>()>>(dd, dd);
};

template <class M>
concept HasAnalyticGradH = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.grad_H(x, x, out, out);
};
template <class M>
concept HasAnalyticHvpH = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.hvp_H(x, x, x, x, out, out);
};

// A Hamiltonian model class behind the batched interface of a model given by H (nonsep::ModelWithGeneralHamiltonian
// and nonsep::ModelWithHamiltonianHessian). Spans must hold count*n numbers (count for values); shorter spans throw
// nonsep::InvalidArgument. Evaluation failures throw EvaluationError. No mutable state.
template <HamiltonianClass M, Derivatives policy = Derivatives::preferred>
class HamiltonianAdapter {
 public:
  static constexpr std::size_t capacity = dimension_capacity<M>();
  using Model = M;

  explicit HamiltonianAdapter(const ParameterValues& values)
      : model_(construct_model<M>(values)), dimension_(model_dimension<M>(values)) {}
  explicit HamiltonianAdapter(M model) requires HasFixedDimension<M> : model_(std::move(model)),
                                                                       dimension_(M::dimension) {}
  HamiltonianAdapter() : HamiltonianAdapter(parse_parameters(parameter_table<M>(), "{}")) {}
  static HamiltonianAdapter from_json(std::string_view parameters_json) {
    return HamiltonianAdapter(parse_parameters(parameter_table<M>(), parameters_json));
  }

  std::size_t dimension() const { return dimension_; }
  const M& model() const { return model_; }

  static constexpr bool analytic_grad_H = policy == Derivatives::preferred && HasAnalyticGradH<M>;
  static constexpr bool analytic_hvp_H = policy == Derivatives::preferred && HasAnalyticHvpH<M>;

  void value_H(std::span<const double> q, std::span<const double> p, std::span<double> out, std::size_t count) const {
    check_sizes(q, p, out.size(), count, 1);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b)
      out[b] = model_.H(Vector<double>(q.data() + b * n, n), Vector<double>(p.data() + b * n, n));
  }

  void grad_H(std::span<const double> q, std::span<const double> p, std::span<double> dH_dq, std::span<double> dH_dp,
              std::size_t count) const {
    check_sizes(q, p, std::min(dH_dq.size(), dH_dp.size()), count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t at = b * n;
      if constexpr (analytic_grad_H) {
        model_.grad_H(Vector<double>(q.data() + at, n), Vector<double>(p.data() + at, n),
                      std::span<double>(dH_dq.data() + at, n), std::span<double>(dH_dp.data() + at, n));
      } else {
        std::array<double, 2 * capacity> z, g;
        std::copy_n(q.data() + at, n, z.data());
        std::copy_n(p.data() + at, n, z.data() + n);
        detail::gradient_by_dual<2 * capacity>(of_phase_point(n), z.data(), 2 * n, g.data());
        std::copy_n(g.data(), n, dH_dq.data() + at);
        std::copy_n(g.data() + n, n, dH_dp.data() + at);
      }
    }
  }

  // The Hessian of H times (dq, dp) at each state (core hamiltonian_gradient.hpp, ModelWithHamiltonianHessian; the
  // form is ignored: H is the model's own).
  void hvp_H(HamiltonianForm, std::span<const double> q, std::span<const double> p, std::span<const double> dq,
             std::span<const double> dp, std::span<double> out_q, std::span<double> out_p, std::size_t count) const {
    check_sizes(q, p, std::min(out_q.size(), out_p.size()), count, dimension_);
    check_sizes(dq, dp, std::min(out_q.size(), out_p.size()), count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t at = b * n;
      if constexpr (analytic_hvp_H) {
        model_.hvp_H(Vector<double>(q.data() + at, n), Vector<double>(p.data() + at, n),
                     Vector<double>(dq.data() + at, n), Vector<double>(dp.data() + at, n),
                     std::span<double>(out_q.data() + at, n), std::span<double>(out_p.data() + at, n));
      } else {
        std::array<double, 2 * capacity> z, v, out;
        std::copy_n(q.data() + at, n, z.data());
        std::copy_n(p.data() + at, n, z.data() + n);
        std::copy_n(dq.data() + at, n, v.data());
        std::copy_n(dp.data() + at, n, v.data() + n);
        const double value =
            detail::hessian_vector_by_dual<2 * capacity>(of_phase_point(n), z.data(), v.data(), 2 * n, out.data());
        detail::poison_if_not_finite(value, out.data(), 2 * n);
        std::copy_n(out.data(), n, out_q.data() + at);
        std::copy_n(out.data() + n, n, out_p.data() + at);
      }
    }
  }

 private:
  // The dimension of the states, a compile-time constant for a model of fixed dimension (loops unroll).
  std::size_t batch_dimension() const {
    if constexpr (HasFixedDimension<M>)
      return M::dimension;
    else
      return dimension_;
  }
  // H as a function of the phase point z = (q, p) of 2n components, for automatic differentiation.
  auto of_phase_point(std::size_t n) const {
    return [this, n](auto z) { return model_.H(z.first(n), z.subspan(n, n)); };
  }
  void check_sizes(std::span<const double> q, std::span<const double> p, std::size_t out_size, std::size_t count,
                   std::size_t out_per_state) const {
    if (q.size() < count * dimension_ || p.size() < count * dimension_ || out_size < count * out_per_state) [[unlikely]]
      throw_bad_batch_sizes(count, dimension_, std::min(q.size(), p.size()), out_size);
  }

  M model_;
  std::size_t dimension_;
};

// How the adapter's automatic derivatives are computed, in words (the metadata's "automatic_differentiation").
template <class Adapter>
std::string hamiltonian_differentiation_text() {
  return "forward mode over H(q, p) with " + std::to_string(2 * Adapter::capacity) +
         " tangents per number (q and p together): the gradient in one pass, the Hessian times a tangent (hvp_H) "
         "in one pass";
}

}  // namespace nonsep::sdk
