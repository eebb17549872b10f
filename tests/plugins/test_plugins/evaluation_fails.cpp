// An SDK plugin with a domain: V = -log(1 - q^2) exists only for |q| < 1. The analytic grad V refuses the rest
// with EvaluationError (a failure); the automatic Hessian of V meets log of a negative number, which the SDK returns
// as NaN (a number: the host would report the trajectory as diverged).
#include <cmath>
#include <nonsep/plugin_sdk.hpp>
#include <string>

struct EvaluationFails {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] * p[0] / 2.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    using std::log;
    return -log(1.0 - q[0] * q[0]);
  }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    if (std::abs(q[0]) >= 1.0)
      throw nonsep::sdk::EvaluationError("V = -log(1 - q^2) needs |q| < 1 (found q = " + std::to_string(q[0]) + ")");
    out[0] = 2.0 * q[0] / (1.0 - q[0] * q[0]);
  }
};

NONSEP_EXPORT_MODEL(EvaluationFails, "evaluation_fails", "0.1", "test plugin: V defined for |q| < 1 only",
                    "T = p^2/2, V = -log(1 - q^2)");
