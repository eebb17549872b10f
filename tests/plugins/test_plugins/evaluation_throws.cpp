// An SDK plugin whose grad T throws an ordinary C++ exception (a bug in a model): the SDK must catch it inside
// the plugin and return NONSEP_INTERNAL_ERROR with the exception's text. The parameters make it throw only in part
// of phase space (grad T where |p| > throw_above_p, grad V where |q| > throw_above_q), so a trajectory can fail
// partway, at a step that depends on its state alone (not on how many calls came before). H_TTV = p^2, whose
// orbits are q = q0 + 2 p0 t.
#include <cmath>
#include <nonsep/plugin_sdk.hpp>
#include <stdexcept>

struct EvaluationThrows {
  static constexpr std::size_t dimension = 1;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "throw_above_p",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = -1.0,
       .description = "grad T throws where |p| is above this (default -1: everywhere)"},
      {.name = "throw_above_q",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 1e300,
       .description = "grad V throws where |q| is above this (default 1e300: nowhere)"}};

  explicit EvaluationThrows(const nonsep::sdk::ParameterValues& values)
      : throw_above_p(values.number("throw_above_p")), throw_above_q(values.number("throw_above_q")) {}
  double throw_above_p, throw_above_q;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] / 2.0;
  }
  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const {
    if (std::abs(p[0]) > throw_above_p) throw std::out_of_range("deliberate bug: index 7 out of range in grad_T");
    out[0] = p[0];
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    if (std::abs(q[0]) > throw_above_q) throw std::domain_error("deliberate bug: q beyond the table in grad_V");
    out[0] = q[0];
  }
};

NONSEP_EXPORT_MODEL(EvaluationThrows, "evaluation_throws", "0.1", "test plugin: grad T throws", "T = p^2/2, V = q^2/2");
