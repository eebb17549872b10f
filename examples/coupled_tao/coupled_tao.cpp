// Two coupled Tao oscillators as a nonsep model, written as a new user would: T and V as templates, nothing else
// (every derivative by the SDK's automatic differentiation), one export line.
//   T(p) = sum_i (p_i sqrt(1 + p_i^2) + asinh p_i) / (2 sqrt 2), so that T'(p_i) = sqrt((1 + p_i^2)/2);
//   V(q) = sum_i (q_i^2/2 + q_i^4/12) + coupling q0^2 q1^2.
// Its formula twin is coupled_tao_formula.json (the same T and V as formulas); the two give the same numbers to
// rounding, and docs/writing-models.md compares their speed.
#include <cmath>
#include <nonsep/plugin_sdk.hpp>

struct CoupledTao {
  static constexpr std::size_t dimension = 2;
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "coupling",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 0.2,
                                                           .description = "c in V = ... + c q0^2 q1^2"}};

  explicit CoupledTao(const nonsep::sdk::ParameterValues& values) : coupling(values.number("coupling")) {}
  double coupling;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    using std::asinh, std::sqrt;
    S sum = 0.0;
    for (const S& x : p) sum += (x * sqrt(1.0 + x * x) + asinh(x)) / (2.0 * std::sqrt(2.0));
    return sum;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    S sum = coupling * q[0] * q[0] * q[1] * q[1];
    for (const S& x : q) sum += x * x / 2.0 + x * x * x * x / 12.0;
    return sum;
  }
};

NONSEP_EXPORT_MODEL(CoupledTao, "coupled_tao", "1.0.0",
                    "Two coupled Tao oscillators, T and V only (an example of automatic derivatives)",
                    "T = sum (p sqrt(1 + p^2) + asinh p)/(2 sqrt 2), V = sum (q^2/2 + q^4/12) + coupling q0^2 q1^2: "
                    "H_TTV = sum_ij T'(p_i) V_ij(q) T'(p_j) with T'(p) = sqrt((1 + p^2)/2)");
