// A model whose written-out fourth derivative of V is wrong (T = p + p^3/6, V = q^2/2 + q^4/12 as paper1d, V'''' = 2,
// given as 3), so that `nonsep inspect --check` must fail on hvp_H in the form that takes V's fourth derivative (TTV)
// and pass the other (VVT takes T's, which is right); everything else is right.
#include <nonsep/plugin_sdk.hpp>

struct WrongFourth {
  static constexpr std::size_t dimension = 1;
  using Vector = nonsep::sdk::Vector<double>;

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] + p[0] * p[0] * p[0] / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] / 2.0 + q[0] * q[0] * q[0] * q[0] / 12.0;
  }
  void hvp_T(Vector p, Vector v, std::span<double> out) const { out[0] = p[0] * v[0]; }
  void hvp_V(Vector q, Vector v, std::span<double> out) const { out[0] = (1.0 + q[0] * q[0]) * v[0]; }
  void d3T(Vector, Vector a, Vector b, std::span<double> out) const { out[0] = a[0] * b[0]; }
  void d3V(Vector q, Vector a, Vector b, std::span<double> out) const { out[0] = 2.0 * q[0] * a[0] * b[0]; }
  void d4T(Vector, Vector, Vector, Vector, std::span<double> out) const { out[0] = 0.0; }
  void d4V(Vector, Vector a, Vector b, Vector c, std::span<double> out) const { out[0] = 3.0 * a[0] * b[0] * c[0]; }
};

NONSEP_EXPORT_MODEL(WrongFourth, "wrong_fourth", "0.1", "a written-out fourth derivative of V that is wrong",
                    "T = p + p^3/6, V = q^2/2 + q^4/12 (d4V gives 3 instead of 2 on purpose)");
