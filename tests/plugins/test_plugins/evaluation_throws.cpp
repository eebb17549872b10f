// An SDK plugin whose grad T throws an ordinary C++ exception (a bug in a model): the SDK must catch it inside
// the plugin and return NONSEP_INTERNAL_ERROR with the exception's text.
#include <stdexcept>

#include <nonsep/plugin_sdk.hpp>

struct EvaluationThrows {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] / 2.0;
  }
  void grad_T(nonsep::sdk::Vector<double>, std::span<double>) const {
    throw std::out_of_range("deliberate bug: index 7 out of range in grad_T");
  }
};

NONSEP_EXPORT_MODEL(EvaluationThrows, "evaluation_throws", "0.1", "test plugin: grad T throws",
                    "T = p^2/2, V = q^2/2");
