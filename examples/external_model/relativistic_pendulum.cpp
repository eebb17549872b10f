// A relativistic pendulum as a nonsep model, written as a new user would: one class, derivatives by automatic
// differentiation, one export line.
//   T(p) = sqrt(1 + p^2),  V(q) = g (1 - cos q)
// so the integrators solve H_TTV = T'(p)^2 V''(q) = g cos(q) p^2 / (1 + p^2).
#include <cmath>
#include <nonsep/plugin_sdk.hpp>

struct RelativisticPendulum {
  static constexpr std::size_t dimension = 1;
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "g",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 1.0,
                                                           .minimum = 0.0,
                                                           .unit = "1/time^2",
                                                           .description = "gravitational acceleration over length"}};

  explicit RelativisticPendulum(const nonsep::sdk::ParameterValues& values) : g(values.number("g")) {}
  double g;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    using std::sqrt;
    return sqrt(1.0 + p[0] * p[0]);
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    using std::cos;
    return g * (1.0 - cos(q[0]));
  }
};

NONSEP_EXPORT_MODEL(RelativisticPendulum, "relativistic_pendulum", "1.0.0",
                    "A pendulum with relativistic kinetic energy (an example of a model built outside nonsep)",
                    "T = sqrt(1 + p^2), V = g (1 - cos q); H_TTV = g cos(q) p^2 / (1 + p^2)");
