#pragma once
// What a plugin model class looks like, and ModelAdapter, which turns one into a batched nonsep model
// (nonsep/core/base/model.hpp) with derivatives by automatic differentiation or by the author's own code.
//
// A model class M (see plugins/paper1d/paper1d.hpp for a complete one) has
//   template <class S> S T(nonsep::sdk::Vector<S> p) const;      the kinetic term T(p)
//   template <class S> S V(nonsep::sdk::Vector<S> q) const;      the potential term V(q)
// written once for any scalar S (double and the dual numbers of dual.hpp), and its dimension, either
//   static constexpr std::size_t dimension = 2;                  fixed, or
//   static constexpr std::size_t max_dimension = 16;             set by an integer parameter (declared in the
//   static constexpr const char* dimension_parameter = "dimension";  table, with 1 <= minimum, maximum <=
//   max_dimension)
// Optionally:
//   static constexpr nonsep::sdk::Parameter parameters[] = {...};   (parameters.hpp)
//   explicit M(const nonsep::sdk::ParameterValues&);                 otherwise M is default-constructed
//   void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const;      analytic derivatives of one
//   void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const;      state (out has n entries, or
//   void hessian_T(nonsep::sdk::Vector<double> p, std::span<double> out) const;   n*n row-major for Hessians);
//   void hessian_V(nonsep::sdk::Vector<double> q, std::span<double> out) const;   each one replaces AD for it;
//   void d3T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> u, std::span<double> out) const;
//   void d3V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> u, std::span<double> out) const;
//                                     directional third derivatives, out[k] = sum_ij T_ijk u_i u_j (n entries).
//   void hvp_T(nonsep::sdk::Vector<double> p, nonsep::sdk::Vector<double> v, std::span<double> out) const;
//   void hvp_V(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> v, std::span<double> out) const;
//                                     Hessian-vector products, out[i] = sum_j T_ij v_j (n entries): what the energy
//                                     and the tangent map of a large sparse model cost (plugins/lattice_chain).
//   void d3T(Vector<double> p, Vector<double> a, Vector<double> b, std::span<double> out) const;
//   void d4T(Vector<double> p, Vector<double> a, Vector<double> b, Vector<double> c, std::span<double> out) const;
//                                     the mixed third and the fourth derivatives, out[k] = sum_ij T_kij a_i b_j and
//                                     sum_ijl T_kijl a_i b_j c_l; both, with hvp_T, replace hvp_H's passes over T
//                                     (and d3V, d4V with hvp_V those over V: plugins/paper2d).
//   double energy_TTV(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> p) const;
//   double energy_VVT(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double> p) const;
//                                     the product term of H written out, T'(p).V''(q)T'(p) (resp. V'(q).T''(p)V'(q)),
//                                     without K + U: one pass for a sparse model's energy (plugins/lattice_chain).
//   template <class S> S K(nonsep::sdk::Vector<S> p) const;      a separable part: H = T_i V_ij T_j + K(p) + U(q)
//   template <class S> S U(nonsep::sdk::Vector<S> q) const;      (either or both; the other is zero)
//   void grad_K(...), grad_U(...), hessian_K(...), hessian_U(...)  analytic derivatives of K and U, as for T and V
// K and U are differentiated automatically like T and V (gradients and Hessians: they must compile for double and
// the gradient and Hessian duals). A model with K or U makes the adapter a nonsep::ModelWithSeparablePart
// (has_K(), has_U(), grad_K, grad_U, value_K, value_U, hessian_K, hessian_U; the absent one's functions write
// zeros); a model with neither leaves the adapter as it was, without those functions.
// The gradients may be written as templates over the number type, like T and V,
//   template <class S> void grad_T(nonsep::sdk::Vector<S> p, std::span<S> out) const;   (and grad_V)
// instantiated for double, Dual<double, 1> and Dual<Dual<double, 1>, 1>. Then every higher derivative not written
// by hand is automatic differentiation of the gradient, not of T: the Hessian-vector products hvp_T, hvp_V in one
// pass (a few gradients' cost, whatever n), the directional third derivatives in one second-order pass along u,
// Hessians in n passes; no capacity-sized dual is used, so max_dimension may be large (a lattice of 10^6 sites),
// and T and V need only compile for double. Their scratch is a per-thread buffer of 2n numbers that grows once.
// The directional derivative of grad H (hvp_H, plugin_abi.h), which the comparators' tangent maps need, reaches fourth
// derivatives: the written-out d3T, d4T (d3V, d4V) above, else one pass of the gradient templates on
// Dual<Dual<Dual<double, 1>, 1>, 1> (O(n)), else of T and V on FourthDerivativeDual<K> (automatic_derivatives.hpp); a
// model with none of these for T or for V has no hvp_H.
// Model code signals a point where it cannot be evaluated by throwing EvaluationError; the plugin returns
// NONSEP_EVALUATION_FAILED with that message. Any other exception becomes NONSEP_INTERNAL_ERROR.
//
// Otherwise automatic differentiation (automatic_derivatives.hpp) uses Dual<double, K> for gradients (one pass),
// Dual<Dual<double, K>, 1> for Hessians (one pass per column) and Dual<Dual<Dual<double, K>, 1>, 1> for directional
// third derivatives (one pass) and Hessian-vector products (one pass), with K = dimension or max_dimension: T and V
// must compile for these three types and double. All AD storage is on the stack (std::array of K duals), so there is no
// heap allocation while evaluating; max_dimension bounds that stack use (about 32 (K+1) K bytes for a third-derivative
// pass, 8.7 KB at K = 16).
//
// Non-finite results are numbers, not failures: a gradient, Hessian or value that overflows or is NaN is returned
// as computed, and the host sees the state become non-finite and reports the trajectory as diverged (where, when
// and which variable). Where automatic differentiation has no meaning (a function outside its domain, as log(-1),
// whose formula 1/x would give -1) the function's own derivative rule gives NaN (dual.hpp), so that such a point
// diverges too instead of silently continuing with a wrong number. A gradient pass by automatic differentiation
// leaves the value of T or V unused, so the compiler drops the work that only the value needs (T = asinh(p) + ...
// computes no asinh for grad T): written with templated T and V alone, gradients cost about what written-out
// ones do (docs/writing-models.md measures it). Hessian, Hessian-vector and third-derivative passes compute the
// value anyway and also set their results to NaN where it is not finite (a T or V that returns NaN by its own
// code). Failures are what model code throws (EvaluationError and other exceptions).
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/model.hpp"
#include "nonsep/sdk/automatic_derivatives.hpp"
#include "nonsep/sdk/dual.hpp"
#include "nonsep/sdk/hamiltonian_products.hpp"
#include "nonsep/sdk/parameters.hpp"

namespace nonsep::sdk {

// Thrown by model code where T or V cannot be evaluated (outside its domain, say). A non-finite number is not
// an error: return it, and the host reports the trajectory as diverged.
class EvaluationError : public nonsep::ModelError {
 public:
  using nonsep::ModelError::ModelError;
};

// Which derivatives an adapter uses: the author's analytic functions where they exist (preferred), or automatic
// differentiation everywhere (automatic; to check analytic code or measure its benefit).
enum class Derivatives { preferred, automatic };

template <class M>
concept HasFixedDimension = requires {
  std::integral_constant<std::size_t, M::dimension>{};
};

template <class M>
concept HasParameterDimension = requires {
  std::integral_constant<std::size_t, M::max_dimension>{};
  { M::dimension_parameter } -> std::convertible_to<std::string_view>;
};

template <class M>
concept HasParameterTable = requires {
  std::span<const Parameter>(M::parameters);
};

template <class M>
consteval std::size_t dimension_capacity() {
  if constexpr (HasFixedDimension<M>)
    return M::dimension;
  else if constexpr (HasParameterDimension<M>)
    return M::max_dimension;
  else
    return 0;
}

// The number types a gradient template is instantiated with for Hessian-vector products and third derivatives.
using DirectionalDual = Dual<double, 1>;
using SecondDirectionalDual = Dual<DirectionalDual, 1>;

template <class M>
concept HasGradientTemplates = requires(const M& m, Vector<DirectionalDual> d, std::span<DirectionalDual> d_out,
                                        Vector<SecondDirectionalDual> dd, std::span<SecondDirectionalDual> dd_out) {
  m.template grad_T<DirectionalDual>(d, d_out);
  m.template grad_V<DirectionalDual>(d, d_out);
  m.template grad_T<SecondDirectionalDual>(dd, dd_out);
  m.template grad_V<SecondDirectionalDual>(dd, dd_out);
};

// The number type and the concepts of the fourth derivatives the directional derivative of grad H needs (hvp_H).
using ThirdDirectionalDual = Dual<SecondDirectionalDual, 1>;
template <class M>
concept HasFourthOrderGradientTemplates = requires(const M& m, Vector<ThirdDirectionalDual> d,
                                                   std::span<ThirdDirectionalDual> out) {
  m.template grad_T<ThirdDirectionalDual>(d, out);
  m.template grad_V<ThirdDirectionalDual>(d, out);
};
template <class M>
concept HasFourthOrderTV = requires(const M& m, Vector<FourthDerivativeDual<dimension_capacity<M>()>> d) {
  m.template T<FourthDerivativeDual<dimension_capacity<M>()>>(d);
  m.template V<FourthDerivativeDual<dimension_capacity<M>()>>(d);
};
template <class M>
concept HasGradientTemplateK = requires(const M& m, Vector<DirectionalDual> d, std::span<DirectionalDual> out) {
  m.template grad_K<DirectionalDual>(d, out);
};
template <class M>
concept HasGradientTemplateU = requires(const M& m, Vector<DirectionalDual> d, std::span<DirectionalDual> out) {
  m.template grad_U<DirectionalDual>(d, out);
};

template <class M>
concept HasDualTV = requires(const M& m, Vector<GradientDual<dimension_capacity<M>()>> d,
                             Vector<HessianDual<dimension_capacity<M>()>> dd,
                             Vector<ThirdDerivativeDual<dimension_capacity<M>()>> ddd) {
  m.template T<GradientDual<dimension_capacity<M>()>>(d);
  m.template V<GradientDual<dimension_capacity<M>()>>(d);
  m.template T<HessianDual<dimension_capacity<M>()>>(dd);
  m.template V<HessianDual<dimension_capacity<M>()>>(dd);
  m.template T<ThirdDerivativeDual<dimension_capacity<M>()>>(ddd);
  m.template V<ThirdDerivativeDual<dimension_capacity<M>()>>(ddd);
};

// The optional separable part K(p), U(q), with what automatic differentiation needs (gradients and Hessians).
template <class M>
concept HasK = requires(const M& m, Vector<double> x, Vector<GradientDual<dimension_capacity<M>()>> d,
                        Vector<HessianDual<dimension_capacity<M>()>> dd) {
  { m.template K<double>(x) } -> std::convertible_to<double>;
  m.template K<GradientDual<dimension_capacity<M>()>>(d);
  m.template K<HessianDual<dimension_capacity<M>()>>(dd);
};
template <class M>
concept HasU = requires(const M& m, Vector<double> x, Vector<GradientDual<dimension_capacity<M>()>> d,
                        Vector<HessianDual<dimension_capacity<M>()>> dd) {
  { m.template U<double>(x) } -> std::convertible_to<double>;
  m.template U<GradientDual<dimension_capacity<M>()>>(d);
  m.template U<HessianDual<dimension_capacity<M>()>>(dd);
};
template <class M>
concept HasAnalyticGradK = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.grad_K(x, out);
};
template <class M>
concept HasAnalyticGradU = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.grad_U(x, out);
};
template <class M>
concept HasAnalyticHessianK = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.hessian_K(x, out);
};
template <class M>
concept HasAnalyticHessianU = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.hessian_U(x, out);
};

template <class M>
concept ModelClass = (HasFixedDimension<M> != HasParameterDimension<M>)&&(dimension_capacity<M>() > 0) &&
                     requires(const M& m, Vector<double> x) {
  { m.template T<double>(x) } -> std::convertible_to<double>;
  { m.template V<double>(x) } -> std::convertible_to<double>;
}
&&(HasGradientTemplates<M> || HasDualTV<M>);

template <class M>
concept HasAnalyticGradT = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.grad_T(x, out);
};
template <class M>
concept HasAnalyticGradV = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.grad_V(x, out);
};
template <class M>
concept HasAnalyticHessianT = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.hessian_T(x, out);
};
template <class M>
concept HasAnalyticHessianV = requires(const M& m, Vector<double> x, std::span<double> out) {
  m.hessian_V(x, out);
};
template <class M>
concept HasAnalyticD3T = requires(const M& m, Vector<double> x, Vector<double> u, std::span<double> out) {
  m.d3T(x, u, out);
};
template <class M>
concept HasAnalyticD3V = requires(const M& m, Vector<double> x, Vector<double> u, std::span<double> out) {
  m.d3V(x, u, out);
};
// The mixed third and the fourth derivatives hvp_H takes (optional, both of T or of V, with that function's hvp):
// d3T(p, a, b, out) writes out_k = T_kij(p) a_i b_j and d4T(p, a, b, c, out) out_k = T_kijl(p) a_i b_j c_l; the same
// for V at q.
template <class M>
concept HasAnalyticMixedT = requires(const M& m, Vector<double> x, Vector<double> u, std::span<double> out) {
  m.d3T(x, u, u, out);
  m.d4T(x, u, u, u, out);
};
template <class M>
concept HasAnalyticMixedV = requires(const M& m, Vector<double> x, Vector<double> u, std::span<double> out) {
  m.d3V(x, u, u, out);
  m.d4V(x, u, u, u, out);
};
template <class M>
concept HasAnalyticHvpT = requires(const M& m, Vector<double> x, Vector<double> v, std::span<double> out) {
  m.hvp_T(x, v, out);
};
template <class M>
concept HasAnalyticHvpV = requires(const M& m, Vector<double> x, Vector<double> v, std::span<double> out) {
  m.hvp_V(x, v, out);
};
template <class M>
concept HasAnalyticEnergyTTV = requires(const M& m, Vector<double> q, Vector<double> p) {
  { m.energy_TTV(q, p) } -> std::convertible_to<double>;
};
template <class M>
concept HasAnalyticEnergyVVT = requires(const M& m, Vector<double> q, Vector<double> p) {
  { m.energy_VVT(q, p) } -> std::convertible_to<double>;
};

// The parameter table of M (empty when M declares none).
template <class M>
constexpr std::span<const Parameter> parameter_table() {
  if constexpr (HasParameterTable<M>)
    return std::span<const Parameter>(M::parameters);
  else
    return {};
}

// Compile-time checks of a model's declarations; each false result is a static_assert in PluginTable.
template <class M>
consteval bool parameter_names_are_unique() {
  constexpr auto table = parameter_table<M>();
  for (std::size_t i = 0; i < table.size(); ++i)
    for (std::size_t j = i + 1; j < table.size(); ++j)
      if (std::string_view(table[i].name) == table[j].name) return false;
  return true;
}
template <class M>
consteval bool parameter_defaults_are_in_range() {
  for (const auto& p : parameter_table<M>()) {
    if (p.minimum && p.default_value < *p.minimum) return false;
    if (p.maximum && p.default_value > *p.maximum) return false;
  }
  return true;
}
template <class M>
consteval bool dimension_parameter_is_bounded() {
  if constexpr (HasParameterDimension<M>) {
    for (const auto& p : parameter_table<M>())
      if (std::string_view(p.name) == std::string_view(M::dimension_parameter))
        return p.type == ParameterType::integer && p.minimum && *p.minimum >= 1.0 && p.maximum &&
               *p.maximum <= static_cast<double>(M::max_dimension);
    return false;
  } else {
    return true;
  }
}

// A model object of class M (a product-form model here, or one given by H: hamiltonian_adapter.hpp) from checked
// parameters: M(values) where M has that constructor, else M().
template <class M>
M construct_model(const ParameterValues& values) {
  if constexpr (std::is_constructible_v<M, const ParameterValues&>)
    return M(values);
  else
    return M();
}
// Its dimension: the fixed one, or the dimension parameter's value. Throws InvalidParameter for one outside
// 1..max_dimension.
template <class M>
std::size_t model_dimension(const ParameterValues& values) {
  if constexpr (HasFixedDimension<M>) {
    return M::dimension;
  } else {
    const std::int64_t n = values.integer(M::dimension_parameter);
    if (n < 1 || static_cast<std::size_t>(n) > M::max_dimension)
      throw InvalidParameter(M::dimension_parameter, "parameter '" + std::string(M::dimension_parameter) +
                                                         "' = " + std::to_string(n) + " is outside 1.." +
                                                         std::to_string(M::max_dimension));
    return static_cast<std::size_t>(n);
  }
}
// The failure of a batch whose spans are too short for its states (a caller's bug).
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_bad_batch_sizes(std::size_t count, std::size_t n,
                                                                         std::size_t in_size, std::size_t out_size) {
  throw nonsep::InvalidArgument("batch of " + std::to_string(count) + " states of dimension " + std::to_string(n) +
                                " given spans of " + std::to_string(in_size) + " and " + std::to_string(out_size) +
                                " numbers");
}

// A model class behind the batched interface of nonsep/core/base/model.hpp (it models
// nonsep::ModelWithThirdDerivatives), plus value_T / value_V and hvp_T / hvp_V. Batch layout as in model.hpp. Spans
// must hold at least count*n (count*n*n for Hessians, count for values) entries; shorter spans are a caller bug and
// throw nonsep::InvalidArgument. Evaluation failures throw EvaluationError. ModelAdapter keeps no mutable state:
// concurrent calls are as safe as M's const member functions.
template <ModelClass M, Derivatives policy = Derivatives::preferred>
class ModelAdapter {
 public:
  static constexpr std::size_t capacity = dimension_capacity<M>();
  using Model = M;

  // The model built from checked parameters (see parse_parameters), dimension from the table when it is a
  // parameter. Throws InvalidParameter (from M's constructor, or a dimension out of 1..max_dimension).
  explicit ModelAdapter(const ParameterValues& values) : model_(construct(values)), dimension_(dimension_of(values)) {}
  // A model object built by the caller (fixed-dimension models only).
  explicit ModelAdapter(M model) requires HasFixedDimension<M> : model_(std::move(model)), dimension_(M::dimension) {}
  // The model with all parameters at their defaults.
  ModelAdapter() : ModelAdapter(parse_parameters(parameter_table<M>(), "{}")) {}
  // Parses and checks `parameters_json` first (parse_parameters).
  static ModelAdapter from_json(std::string_view parameters_json) {
    return ModelAdapter(parse_parameters(parameter_table<M>(), parameters_json));
  }

  std::size_t dimension() const { return dimension_; }
  const M& model() const { return model_; }

  static constexpr bool analytic_grad_T = policy == Derivatives::preferred && HasAnalyticGradT<M>;
  static constexpr bool analytic_grad_V = policy == Derivatives::preferred && HasAnalyticGradV<M>;
  static constexpr bool analytic_hessian_T = policy == Derivatives::preferred && HasAnalyticHessianT<M>;
  static constexpr bool analytic_hessian_V = policy == Derivatives::preferred && HasAnalyticHessianV<M>;
  static constexpr bool analytic_d3T = policy == Derivatives::preferred && HasAnalyticD3T<M>;
  static constexpr bool analytic_d3V = policy == Derivatives::preferred && HasAnalyticD3V<M>;
  static constexpr bool analytic_hvp_T = policy == Derivatives::preferred && HasAnalyticHvpT<M>;
  static constexpr bool analytic_hvp_V = policy == Derivatives::preferred && HasAnalyticHvpV<M>;
  static constexpr bool analytic_energy_TTV = policy == Derivatives::preferred && HasAnalyticEnergyTTV<M>;
  static constexpr bool analytic_energy_VVT = policy == Derivatives::preferred && HasAnalyticEnergyVVT<M>;
  // Higher derivatives by automatic differentiation of the gradient templates (else of T and V).
  static constexpr bool differentiates_gradients = policy == Derivatives::preferred && HasGradientTemplates<M>;
  static_assert(differentiates_gradients || HasDualTV<M>,
                "Derivatives::automatic needs T and V that compile for the dual numbers of automatic_derivatives.hpp");
  // The fourth derivatives of hvp_H: written out (analytic_mixed_T, _V below), else of the gradient templates where
  // they compile for ThirdDirectionalDual, else of T and V on FourthDerivativeDual; a model with none has no hvp_H.
  static constexpr bool fourth_by_gradients = differentiates_gradients && HasFourthOrderGradientTemplates<M>;
  // hvp_H's passes over T (V) replaced by the model's written-out d3T, d4T and hvp_T (d3V, d4V, hvp_V).
  static constexpr bool analytic_mixed_T = policy == Derivatives::preferred && HasAnalyticMixedT<M> && analytic_hvp_T;
  static constexpr bool analytic_mixed_V = policy == Derivatives::preferred && HasAnalyticMixedV<M> && analytic_hvp_V;
  static constexpr bool has_hamiltonian_hessian =
      fourth_by_gradients || HasFourthOrderTV<M> || (analytic_mixed_T && analytic_mixed_V);

  static constexpr bool analytic_grad_K = policy == Derivatives::preferred && HasAnalyticGradK<M>;
  static constexpr bool analytic_grad_U = policy == Derivatives::preferred && HasAnalyticGradU<M>;
  static constexpr bool analytic_hessian_K = policy == Derivatives::preferred && HasAnalyticHessianK<M>;
  static constexpr bool analytic_hessian_U = policy == Derivatives::preferred && HasAnalyticHessianU<M>;

  // The dimension of the states, a compile-time constant for a model of fixed dimension, so that the loops over a
  // batch unroll and vectorize.
  std::size_t batch_dimension() const {
    if constexpr (HasFixedDimension<M>)
      return M::dimension;
    else
      return dimension_;
  }

  void value_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    values(p, out, count, [this](auto v) { return model_.T(v); });
  }
  void value_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    values(q, out, count, [this](auto v) { return model_.V(v); });
  }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    gradients<analytic_grad_T>(
        p, out, count, [this](auto v) { return model_.T(v); },
        [&](Vector<double> x, std::span<double> g) {
          if constexpr (HasAnalyticGradT<M>) model_.grad_T(x, g);
        });
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    gradients<analytic_grad_V>(
        q, out, count, [this](auto v) { return model_.V(v); },
        [&](Vector<double> x, std::span<double> g) {
          if constexpr (HasAnalyticGradV<M>) model_.grad_V(x, g);
        });
  }
  void hessian_T(std::span<const double> p, std::span<double> out, std::size_t count) const {
    if constexpr (!analytic_hessian_T && differentiates_gradients)
      hessians_by_gradient(p, out, count, [this](auto y, auto g) { model_.grad_T(y, g); });
    else
      hessians<analytic_hessian_T>(
          p, out, count, [this](auto w) { return model_.T(w); },
          [&](Vector<double> x, std::span<double> h) {
            if constexpr (HasAnalyticHessianT<M>) model_.hessian_T(x, h);
          });
  }
  void hessian_V(std::span<const double> q, std::span<double> out, std::size_t count) const {
    if constexpr (!analytic_hessian_V && differentiates_gradients)
      hessians_by_gradient(q, out, count, [this](auto y, auto g) { model_.grad_V(y, g); });
    else
      hessians<analytic_hessian_V>(
          q, out, count, [this](auto w) { return model_.V(w); },
          [&](Vector<double> x, std::span<double> h) {
            if constexpr (HasAnalyticHessianV<M>) model_.hessian_V(x, h);
          });
  }

  // The separable part (nonsep::ModelWithSeparablePart), present when M has K or U; the absent one is zero.
  bool has_K() const requires(HasK<M> || HasU<M>) { return HasK<M>; }
  bool has_U() const requires(HasK<M> || HasU<M>) { return HasU<M>; }
  void value_K(std::span<const double> p, std::span<double> out, std::size_t count) const requires(HasK<M> || HasU<M>) {
    if constexpr (HasK<M>)
      values(p, out, count, [this](auto v) { return model_.K(v); });
    else
      zeros(p, out, count, 1);
  }
  void value_U(std::span<const double> q, std::span<double> out, std::size_t count) const requires(HasK<M> || HasU<M>) {
    if constexpr (HasU<M>)
      values(q, out, count, [this](auto v) { return model_.U(v); });
    else
      zeros(q, out, count, 1);
  }
  void grad_K(std::span<const double> p, std::span<double> out, std::size_t count) const requires(HasK<M> || HasU<M>) {
    if constexpr (HasK<M>)
      gradients<analytic_grad_K>(
          p, out, count, [this](auto v) { return model_.K(v); },
          [&](Vector<double> x, std::span<double> g) {
            if constexpr (HasAnalyticGradK<M>) model_.grad_K(x, g);
          });
    else
      zeros(p, out, count, dimension_);
  }
  void grad_U(std::span<const double> q, std::span<double> out, std::size_t count) const requires(HasK<M> || HasU<M>) {
    if constexpr (HasU<M>)
      gradients<analytic_grad_U>(
          q, out, count, [this](auto v) { return model_.U(v); },
          [&](Vector<double> x, std::span<double> g) {
            if constexpr (HasAnalyticGradU<M>) model_.grad_U(x, g);
          });
    else
      zeros(q, out, count, dimension_);
  }
  void hessian_K(std::span<const double> p, std::span<double> out, std::size_t count) const
      requires(HasK<M> || HasU<M>) {
    if constexpr (HasK<M>)
      hessians<analytic_hessian_K>(
          p, out, count, [this](auto v) { return model_.K(v); },
          [&](Vector<double> x, std::span<double> h) {
            if constexpr (HasAnalyticHessianK<M>) model_.hessian_K(x, h);
          });
    else
      zeros(p, out, count, dimension_ * dimension_);
  }
  void hessian_U(std::span<const double> q, std::span<double> out, std::size_t count) const
      requires(HasK<M> || HasU<M>) {
    if constexpr (HasU<M>)
      hessians<analytic_hessian_U>(
          q, out, count, [this](auto v) { return model_.U(v); },
          [&](Vector<double> x, std::span<double> h) {
            if constexpr (HasAnalyticHessianU<M>) model_.hessian_U(x, h);
          });
    else
      zeros(q, out, count, dimension_ * dimension_);
  }

  // out[b*n + k] = sum_ij T_ijk(p_b) u_bi u_bj (d3T), the same for V in q (d3V); u has the layout of p.
  void d3T(std::span<const double> p, std::span<const double> u, std::span<double> out, std::size_t count) const {
    check_sizes(p, out, count, dimension_);
    check_sizes(u, out, count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const double* x = p.data() + b * n;
      const double* v = u.data() + b * n;
      double* d = out.data() + b * n;
      if constexpr (analytic_d3T)
        model_.d3T(Vector<double>(x, n), Vector<double>(v, n), std::span<double>(d, n));
      else if constexpr (differentiates_gradients)
        detail::directional_third_by_gradient([this](auto y, auto g) { model_.grad_T(y, g); }, x, v, n, d);
      else
        detail::poison_if_not_finite(
            detail::directional_third_by_dual<capacity>([this](auto w) { return model_.T(w); }, x, v, n, d), d, n);
    }
  }
  void d3V(std::span<const double> q, std::span<const double> u, std::span<double> out, std::size_t count) const {
    check_sizes(q, out, count, dimension_);
    check_sizes(u, out, count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const double* x = q.data() + b * n;
      const double* v = u.data() + b * n;
      double* d = out.data() + b * n;
      if constexpr (analytic_d3V)
        model_.d3V(Vector<double>(x, n), Vector<double>(v, n), std::span<double>(d, n));
      else if constexpr (differentiates_gradients)
        detail::directional_third_by_gradient([this](auto y, auto g) { model_.grad_V(y, g); }, x, v, n, d);
      else
        detail::poison_if_not_finite(
            detail::directional_third_by_dual<capacity>([this](auto w) { return model_.V(w); }, x, v, n, d), d, n);
    }
  }

  // d3T (d3V) and the Hessian-vector product along the same u, from one pass where both are automatic (the pass of
  // the third derivatives computes the product alongside, with the numbers of hvp_T's own pass): grad H's inner
  // product and third derivatives (core hessian_products.hpp, ModelWithThirdAndProduct).
  void d3T_with_product(std::span<const double> p, std::span<const double> u, std::span<double> out,
                        std::span<double> product, std::size_t count) const requires(!analytic_d3T && !analytic_hvp_T) {
    third_with_product<true>(p, u, out, product, count);
  }
  void d3V_with_product(std::span<const double> q, std::span<const double> u, std::span<double> out,
                        std::span<double> product, std::size_t count) const requires(!analytic_d3V && !analytic_hvp_V) {
    third_with_product<false>(q, u, out, product, count);
  }

  // Hessian-vector products, out[b*n + i] = sum_j T_ij(p_b) v[b*n + j] (hvp_T), the same for V in q (hvp_V); v has
  // the layout of p. The model's own product, or one directional pass over the gradient template, or one
  // Hessian-column pass over T or V.
  void hvp_T(std::span<const double> p, std::span<const double> v, std::span<double> out, std::size_t count) const {
    hessian_vector<analytic_hvp_T>([](const auto& m, auto x, auto w, auto d) { m.hvp_T(x, w, d); },
                                   [](const auto& m, auto y, auto g) { m.grad_T(y, g); },
                                   [](const auto& m, auto w) { return m.T(w); }, p, v, out, count);
  }
  void hvp_V(std::span<const double> q, std::span<const double> v, std::span<double> out, std::size_t count) const {
    hessian_vector<analytic_hvp_V>([](const auto& m, auto x, auto w, auto d) { m.hvp_V(x, w, d); },
                                   [](const auto& m, auto y, auto g) { m.grad_V(y, g); },
                                   [](const auto& m, auto w) { return m.V(w); }, q, v, out, count);
  }

  // The directional derivative of grad H (plugin_abi.h hvp_H, which writes out the formula): the Hessian of the
  // solved H, K + U included, times the tangent (dq, dp) of each state, into out_q = d(dH/dq), out_p = d(dH/dp); all
  // six spans in the gradient layout. Per state three passes, over the gradient templates (O(n) for a sparse model)
  // or over T and V, each seeded so that it also forms what the formula adds to its result (MixedPassExtras,
  // automatic_derivatives.hpp): the gradient and a Hessian-vector product of the outer function (T in TTV) in one
  // pass where it is differentiated automatically, the inner's mixed fourth derivative (third when dq or dp is
  // zero) with its lower derivatives, the outer's mixed third derivative (hamiltonian_products.hpp); plus K'' dp and
  // U'' dq.
  void hvp_H(HamiltonianForm form, std::span<const double> q, std::span<const double> p, std::span<const double> dq,
             std::span<const double> dp, std::span<double> out_q, std::span<double> out_p,
             std::size_t count) const requires has_hamiltonian_hessian {
    const std::size_t size = count * dimension_;
    for (const std::size_t found : {q.size(), p.size(), dq.size(), dp.size(), out_q.size(), out_p.size()})
      if (found < size) [[unlikely]]
        throw_bad_batch_sizes(count, dimension_, std::min({q.size(), p.size(), dq.size(), dp.size()}),
                              std::min(out_q.size(), out_p.size()));
    if (form == HamiltonianForm::TTV)
      detail::ProductPasses(*this).template hamiltonian_products<true>(q.data(), p.data(), dq.data(), dp.data(),
                                                                       out_q.data(), out_p.data(), count);
    else
      detail::ProductPasses(*this).template hamiltonian_products<false>(p.data(), q.data(), dp.data(), dq.data(),
                                                                        out_p.data(), out_q.data(), count);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const std::size_t at = b * n;
      if constexpr (HasK<M>) add_separable_product<true>(p.data() + at, dp.data() + at, out_p.data() + at, n);
      if constexpr (HasU<M>) add_separable_product<false>(q.data() + at, dq.data() + at, out_q.data() + at, n);
    }
  }

  // The model's own product term of H (nonsep::ModelWithProductEnergy, energy.hpp), one number per state; present
  // when M writes out energy_TTV or energy_VVT (has_product_energy says which).
  bool has_product_energy(HamiltonianForm form) const requires(analytic_energy_TTV || analytic_energy_VVT) {
    return form == HamiltonianForm::TTV ? analytic_energy_TTV : analytic_energy_VVT;
  }
  void product_energy(HamiltonianForm form, std::span<const double> q, std::span<const double> p, std::span<double> out,
                      std::size_t count) const requires(analytic_energy_TTV || analytic_energy_VVT) {
    if (!has_product_energy(form))
      throw nonsep::InvalidArgument(std::string("the model does not write out energy_") +
                                    (form == HamiltonianForm::TTV ? "TTV" : "VVT"));
    check_sizes(q, out, count, 1);
    check_sizes(p, out, count, 1);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const Vector<double> qb(q.data() + b * n, n), pb(p.data() + b * n, n);
      if constexpr (analytic_energy_TTV)
        if (form == HamiltonianForm::TTV) out[b] = model_.energy_TTV(qb, pb);
      if constexpr (analytic_energy_VVT)
        if (form == HamiltonianForm::VVT) out[b] = model_.energy_VVT(qb, pb);
    }
  }

 private:
  // d3T_with_product (kinetic) or d3V_with_product: the pass of d3T (d3V) with the product taken alongside.
  template <bool kinetic>
  void third_with_product(std::span<const double> x, std::span<const double> u, std::span<double> out,
                          std::span<double> product, std::size_t count) const {
    check_sizes(x, out, count, dimension_);
    check_sizes(u, product, count, dimension_);
    const std::size_t n = batch_dimension();
    const detail::ProductPasses passes(*this);
    for (std::size_t b = 0; b < count; ++b) {
      const double* v = u.data() + b * n;
      passes.template mixed_third_of<kinetic>(x.data() + b * n, v, v, out.data() + b * n, n,
                                              {.seed = nullptr, .along_a = product.data() + b * n});
    }
  }
  // out += K''(x) v (kinetic) or U''(x) v: one directional pass over grad_K (grad_U) where it is a template, else
  // one Hessian-column pass over K (U).
  template <bool kinetic>
  void add_separable_product(const double* x, const double* v, double* out, std::size_t n) const {
    double* product = detail::GradientScratch<double>::of_size(3 * n).g.data() + 2 * n;  // past hvp_H's use
    if constexpr (kinetic && HasGradientTemplateK<M> && policy == Derivatives::preferred)
      detail::hessian_vector_by_gradient([this](auto y, auto g) { model_.grad_K(y, g); }, x, v, n, product);
    else if constexpr (!kinetic && HasGradientTemplateU<M> && policy == Derivatives::preferred)
      detail::hessian_vector_by_gradient([this](auto y, auto g) { model_.grad_U(y, g); }, x, v, n, product);
    else if constexpr (kinetic)
      detail::poison_if_not_finite(
          detail::hessian_vector_by_dual<capacity>([this](auto w) { return model_.K(w); }, x, v, n, product), product,
          n);
    else
      detail::poison_if_not_finite(
          detail::hessian_vector_by_dual<capacity>([this](auto w) { return model_.U(w); }, x, v, n, product), product,
          n);
    for (std::size_t i = 0; i < n; ++i) out[i] += product[i];
  }

  // f (T, V, K or U) at each state of x, one number per state.
  template <class F>
  void values(std::span<const double> x, std::span<double> out, std::size_t count, const F& f) const {
    check_sizes(x, out, count, 1);
    const std::size_t n = dimension_;
    for (std::size_t b = 0; b < count; ++b) out[b] = f(Vector<double>(x.data() + b * n, n));
  }
  // grad f at each state: the author's `analytic_gradient(x, out)` when `analytic`, automatic differentiation of f
  // otherwise.
  template <bool analytic, class F, class A>
  void gradients(std::span<const double> x, std::span<double> out, std::size_t count, const F& f,
                 const A& analytic_gradient) const {
    check_sizes(x, out, count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const double* at = x.data() + b * n;
      double* g = out.data() + b * n;
      if constexpr (analytic)
        analytic_gradient(Vector<double>(at, n), std::span<double>(g, n));
      else
        detail::gradient_by_dual<capacity>(f, at, n, g);  // the value unused: see the header comment
    }
  }
  // The Hessian of f at each state, row-major n x n: analytic or automatic as gradients().
  template <bool analytic, class F, class A>
  void hessians(std::span<const double> x, std::span<double> out, std::size_t count, const F& f,
                const A& analytic_hessian) const {
    check_sizes(x, out, count, dimension_ * dimension_);
    const std::size_t n = dimension_;
    for (std::size_t b = 0; b < count; ++b) {
      const double* at = x.data() + b * n;
      double* h = out.data() + b * n * n;
      if constexpr (analytic)
        analytic_hessian(Vector<double>(at, n), std::span<double>(h, n * n));
      else
        detail::poison_if_not_finite(detail::hessian_by_dual<capacity>(f, at, n, h), h, n * n);
    }
  }
  // The Hessian of the function whose gradient template is `gradient(y, g)`, column by column (n passes).
  template <class G>
  void hessians_by_gradient(std::span<const double> x, std::span<double> out, std::size_t count,
                            const G& gradient) const {
    check_sizes(x, out, count, dimension_ * dimension_);
    const std::size_t n = dimension_;
    for (std::size_t b = 0; b < count; ++b)
      detail::hessian_by_gradient(gradient, x.data() + b * n, n, out.data() + b * n * n);
  }
  // Hessian-vector products of T or V: the model's `product(model, x, v, out)` when `analytic`, else one directional
  // pass over the gradient template `gradient(model, y, g)`, or one Hessian-column pass over `function(model, w)`.
  template <bool analytic, class Product, class Gradient, class Function>
  void hessian_vector(const Product& product, const Gradient& gradient, const Function& function,
                      std::span<const double> x, std::span<const double> v, std::span<double> out,
                      std::size_t count) const {
    check_sizes(x, out, count, dimension_);
    check_sizes(v, out, count, dimension_);
    const std::size_t n = batch_dimension();
    for (std::size_t b = 0; b < count; ++b) {
      const double* xb = x.data() + b * n;
      const double* vb = v.data() + b * n;
      double* d = out.data() + b * n;
      if constexpr (analytic)
        product(model_, Vector<double>(xb, n), Vector<double>(vb, n), std::span<double>(d, n));
      else if constexpr (differentiates_gradients)
        detail::hessian_vector_by_gradient([&](auto y, auto g) { gradient(model_, y, g); }, xb, vb, n, d);
      else
        detail::poison_if_not_finite(
            detail::hessian_vector_by_dual<capacity>([&](auto w) { return function(model_, w); }, xb, vb, n, d), d, n);
    }
  }
  // The absent part of K + U: zero, with the sizes checked as for the present one.
  void zeros(std::span<const double> x, std::span<double> out, std::size_t count, std::size_t per_state) const {
    check_sizes(x, out, count, per_state);
    std::fill_n(out.begin(), count * per_state, 0.0);
  }

  static M construct(const ParameterValues& values) { return construct_model<M>(values); }
  static std::size_t dimension_of(const ParameterValues& values) { return model_dimension<M>(values); }
  // Inline, its failure out of line: the plugin table calls with spans of exactly count*n numbers (the ABI's batch
  // layout), for which the comparison folds away, so a call through the ABI checks its sizes once, on the host's
  // side.
  void check_sizes(std::span<const double> in, std::span<double> out, std::size_t count,
                   std::size_t out_per_state) const {
    if (in.size() < count * dimension_ || out.size() < count * out_per_state) [[unlikely]]
      throw_bad_batch_sizes(count, dimension_, in.size(), out.size());
  }

  M model_;
  std::size_t dimension_;
};

// How an adapter's automatic derivatives are computed, in words: the plugin metadata's "automatic_differentiation",
// which `nonsep inspect` shows beside each function's "analytic" or "automatic".
template <class Adapter>
std::string automatic_differentiation_text() {
  if constexpr (Adapter::differentiates_gradients)
    return "forward mode over the model's gradient templates: a Hessian-vector product or a directional third "
           "derivative in one pass of 1 tangent, a Hessian in n passes";
  else
    return "forward mode over T and V with " + std::to_string(Adapter::capacity) +
           (Adapter::capacity == 1 ? " tangent" : " tangents") +
           (HasFixedDimension<typename Adapter::Model> ? " per number (the dimension, known at compile time)"
                                                       : " per number (max_dimension)") +
           ": a gradient in one pass (the value of T or V "
           "unused, so not computed), a Hessian in n passes, a Hessian-vector product or a directional third "
           "derivative in one pass";
}

}  // namespace nonsep::sdk
