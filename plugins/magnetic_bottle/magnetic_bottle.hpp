#pragma once
// A charged particle (unit mass and charge) in a static axisymmetric magnetic bottle, with an optional isotropic
// harmonic potential, given by its Hamiltonian H(q, p) (a model given by H itself, plugin_abi.h version 6):
//   H = |p - A(q)|^2 / 2 + omega^2 |q|^2 / 2,    A = (B/2) (1 + mirror z^2) (-y, x, 0),    q = (x, y, z).
// The field B = curl A = B ((-mirror x z, -mirror y z, 1 + mirror z^2)) (div B = 0 exactly) is strongest away from
// the midplane z = 0: with mirror > 0 it reflects particles whose pitch angle is large enough (a magnetic mirror) and
// lets the others escape along z. With mirror = 0 it is a uniform field B along z: then with omega > 0 the motion is
// linear, with an exact solution (the transverse motion a sum of two circular modes of frequencies
// (sqrt(B^2 + 4 omega^2) +- B)/2, z a harmonic oscillator), against which tests/plugins/test_general_hamiltonian.cpp
// checks the integrators. Conserved: H and the canonical angular momentum x p_y - y p_x (the field's axial
// symmetry); with two degrees of freedom left, the motion in the bottle is chaotic for some starts.
// Parameters "B" (default 1), "mirror" (default 0.5, >= 0), "omega" (default 0, >= 0). Defined everywhere.
// Gradient and Hessian-vector products by automatic differentiation of H.
#include <nonsep/plugin_sdk.hpp>

class MagneticBottle {
 public:
  static constexpr std::size_t dimension = 3;
  static constexpr nonsep::sdk::Parameter parameters[] = {
      {.name = "B",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 1.0,
       .description = "field strength on the axis at z = 0 (the cyclotron frequency there)"},
      {.name = "mirror",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.5,
       .minimum = 0.0,
       .description = "curvature of the field along the axis: B_z = B (1 + mirror z^2) on the axis; 0 is a "
                      "uniform field"},
      {.name = "omega",
       .type = nonsep::sdk::ParameterType::number,
       .default_value = 0.0,
       .minimum = 0.0,
       .description = "frequency of the isotropic harmonic potential omega^2 |q|^2 / 2"}};

  explicit MagneticBottle(const nonsep::sdk::ParameterValues& values)
      : B_(values.number("B")), mirror_(values.number("mirror")), omega_(values.number("omega")) {}

  template <class S>
  S H(nonsep::sdk::Vector<S> q, nonsep::sdk::Vector<S> p) const {
    const S a = B_ / 2.0 * (1.0 + mirror_ * q[2] * q[2]);  // A = a (-y, x, 0)
    const S vx = p[0] + a * q[1], vy = p[1] - a * q[0], vz = p[2];
    return (vx * vx + vy * vy + vz * vz) / 2.0 + omega_ * omega_ * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) / 2.0;
  }

 private:
  double B_, mirror_, omega_;
};
