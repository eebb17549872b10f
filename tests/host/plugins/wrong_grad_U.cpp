// A model with a separable part whose analytic grad U is wrong by a factor 2 (U = q^2/2, grad U given as 2q), so
// that `nonsep inspect --check` must name grad_U; T, V and U's value are right.
#include <nonsep/plugin_sdk.hpp>

class WrongGradU {
 public:
  static constexpr std::size_t dimension = 1;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return 0.5 * p[0] * p[0];
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return 0.25 * q[0] * q[0];
  }
  template <class S>
  S U(nonsep::sdk::Vector<S> q) const {
    return 0.5 * q[0] * q[0];
  }
  void grad_U(nonsep::sdk::Vector<double> q, std::span<double> out) const { out[0] = 2.0 * q[0]; }
};

NONSEP_EXPORT_MODEL(WrongGradU, "wrong_grad_U", "0.1", "a separable part with a wrong analytic grad U",
                    "T = p^2/2, V = q^2/4, U = q^2/2 (grad U wrong on purpose)");
