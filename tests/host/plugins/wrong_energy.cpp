// A model whose written-out energy_TTV is wrong by a factor 2 (T = p^2/2, V = q^2/4: H_TTV = p^2/2, given as p^2),
// so that `nonsep inspect --check` must fail on energy_TTV; its energy_VVT (q^2/4) and everything else are right.
#include <nonsep/plugin_sdk.hpp>

class WrongEnergy {
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
  double energy_TTV(nonsep::sdk::Vector<double>, nonsep::sdk::Vector<double> p) const { return p[0] * p[0]; }
  double energy_VVT(nonsep::sdk::Vector<double> q, nonsep::sdk::Vector<double>) const { return 0.25 * q[0] * q[0]; }
};

NONSEP_EXPORT_MODEL(WrongEnergy, "wrong_energy", "0.1", "a written-out energy_TTV that is wrong",
                    "T = p^2/2, V = q^2/4, H_TTV = p^2/2 (energy_TTV gives p^2 on purpose)");
