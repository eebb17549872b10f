#pragma once
// A three-dimensional coupled model with a parameter, for the benchmark's figure 7 (the kernels' ratios on a model
// other than paper1d): the 3-D analogue of plugins/paper2d,
//   T(p) = sum_i (p_i + p_i^3/6),    V(q) = |q|^2/2 + |q|^4/12 + coupling (q1^2 q2^2 + q2^2 q3^2 + q3^2 q1^2),
// grad T_i = 1 + p_i^2/2, grad V_i = q_i (1 + |q|^2/3) + 2 coupling q_i (|q|^2 - q_i^2). Parameter "coupling"
// (default 0.2). Coupled3D is the plugin's model class (coupled3d.cpp); coupled3d_run and coupled3d_run_staged are
// the hand-written basic step on it (as hand_written.hpp on paper1d), with the same operations as the class's
// gradients.
#include <cstddef>
#include <cstdint>
#include <nonsep/plugin_sdk.hpp>

#include "hand_written.hpp"

inline void coupled3d_grad_T(const double* p, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = 1.0 + 0.5 * p[i] * p[i];
}
inline void coupled3d_grad_V(double coupling, const double* q, double* out) {
  const double x2 = q[0] * q[0], y2 = q[1] * q[1], z2 = q[2] * q[2], radial = 1.0 + (x2 + y2 + z2) / 3.0;
  out[0] = q[0] * radial + 2.0 * coupling * q[0] * (y2 + z2);
  out[1] = q[1] * radial + 2.0 * coupling * q[1] * (x2 + z2);
  out[2] = q[2] * radial + 2.0 * coupling * q[2] * (x2 + y2);
}

class Coupled3D {
 public:
  static constexpr std::size_t dimension = 3;
  static constexpr nonsep::sdk::Parameter parameters[] = {{.name = "coupling",
                                                           .type = nonsep::sdk::ParameterType::number,
                                                           .default_value = 0.2,
                                                           .minimum = -0.1,
                                                           .maximum = 0.3,
                                                           .description = "strength of the q_i^2 q_j^2 terms of V"}};
  explicit Coupled3D(const nonsep::sdk::ParameterValues& values) : coupling_(values.number("coupling")) {}

  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return p[0] + p[1] + p[2] + (nonsep::sdk::cube(p[0]) + nonsep::sdk::cube(p[1]) + nonsep::sdk::cube(p[2])) / 6.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S x2 = q[0] * q[0], y2 = q[1] * q[1], z2 = q[2] * q[2], r2 = x2 + y2 + z2;
    return r2 / 2.0 + r2 * r2 / 12.0 + coupling_ * (x2 * y2 + y2 * z2 + z2 * x2);
  }
  void grad_T(nonsep::sdk::Vector<double> p, std::span<double> out) const { coupled3d_grad_T(p.data(), out.data()); }
  void grad_V(nonsep::sdk::Vector<double> q, std::span<double> out) const {
    coupled3d_grad_V(coupling_, q.data(), out.data());
  }

 private:
  double coupling_;
};

namespace bench {

// `steps` basic steps of one state (q, p: 3 numbers each), in place, the state in local arrays.
inline void coupled3d_run(const HandWrittenStep& c, double coupling, double* q, double* p, std::uint64_t steps) {
  double x[3] = {q[0], q[1], q[2]}, y[3] = {p[0], p[1], p[2]}, g[3], t[3];
  coupled3d_grad_V(coupling, x, g);
  const auto kick = [&](double h) {
    for (int i = 0; i < 3; ++i) y[i] += h * g[i];
  };
  const auto drift = [&](double h) {
    coupled3d_grad_T(y, t);
    for (int i = 0; i < 3; ++i) x[i] += h * t[i];
    coupled3d_grad_V(coupling, x, g);
  };
  for (std::uint64_t k = 0; k < steps; ++k) basic_step_stages(c, kick, drift);
  for (int i = 0; i < 3; ++i) q[i] = x[i], p[i] = y[i];
}

// The same for `count` states, stage by stage over all of them (g: 3 count numbers of scratch).
inline void coupled3d_run_staged(const HandWrittenStep& c, double coupling, double* q, double* p, double* g,
                                 std::size_t count, std::uint64_t steps) {
  for (std::size_t b = 0; b < count; ++b) coupled3d_grad_V(coupling, q + 3 * b, g + 3 * b);
  const auto kick = [&](double h) {
    for (std::size_t i = 0; i < 3 * count; ++i) p[i] += h * g[i];
  };
  const auto drift = [&](double h) {
    for (std::size_t b = 0; b < count; ++b) {
      double t[3];
      coupled3d_grad_T(p + 3 * b, t);
      for (int i = 0; i < 3; ++i) q[3 * b + i] += h * t[i];
      coupled3d_grad_V(coupling, q + 3 * b, g + 3 * b);
    }
  };
  for (std::uint64_t k = 0; k < steps; ++k) basic_step_stages(c, kick, drift);
}

}  // namespace bench
