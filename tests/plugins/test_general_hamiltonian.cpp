// The shipped models given by H(q, p) itself (plugin ABI version 6), through the loader: the charged particle in a
// uniform field with an isotropic harmonic potential (magnetic_bottle at mirror 0) against its exact solution with
// gauss 3 stages; the bottle's conserved canonical angular momentum; grad_H and hvp_H against finite differences.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nonsep/core/analysis/energy.hpp"
#include "nonsep/core/schemes/gauss_legendre.hpp"
#include "nonsep/derivative_checker.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"

namespace test_general_hamiltonian {

using nonsep::host::load_plugin;
using nonsep::host::PluginModel;

namespace {

PluginModel shipped(const std::string& name, const nlohmann::json& parameters = nlohmann::json::object()) {
  return load_plugin(std::string(NONSEP_BUILD_PLUGIN_DIR) + "/" + name + ".so", "").create(parameters);
}

// The exact state of H = |p - A|^2/2 + w^2 |q|^2/2 with A = (B/2)(-y, x, 0) at time t from (q, p): with
// u = x + i y, u'' = -i B u' - w^2 u, so u = a e^{i k1 t} + c e^{i k2 t} (k^2 + B k - w^2 = 0); z is a harmonic
// oscillator of frequency w; p = v + A.
std::vector<double> exact_state(double B, double w, const double* q, const double* p, double t) {
  using C = std::complex<double>;
  const C i(0, 1);
  const double root = std::sqrt(B * B + 4 * w * w), k1 = (-B + root) / 2, k2 = (-B - root) / 2;
  const C u0(q[0], q[1]), du0(p[0] + B * q[1] / 2, p[1] - B * q[0] / 2);
  const C a = (du0 - i * k2 * u0) / (i * (k1 - k2)), c = u0 - a;
  const C u = a * std::exp(i * k1 * t) + c * std::exp(i * k2 * t);
  const C du = i * k1 * a * std::exp(i * k1 * t) + i * k2 * c * std::exp(i * k2 * t);
  const double z = q[2] * std::cos(w * t) + p[2] / w * std::sin(w * t);
  const double pz = -q[2] * w * std::sin(w * t) + p[2] * std::cos(w * t);
  return {u.real(), u.imag(), z, du.real() - B * u.imag() / 2, du.imag() + B * u.real() / 2, pz};
}

}  // namespace

TEST_CASE("magnetic_bottle at mirror 0: gauss 3 stages at 1e-12 of the exact state over 100 gyrations") {
  const double B = 1.0, w = 0.5;
  const PluginModel model = shipped("magnetic_bottle", {{"B", B}, {"mirror", 0.0}, {"omega", w}});
  CHECK(model.general_hamiltonian());
  const std::vector<double> q0{1.0, 0.0, 0.5, 0.3, -0.4, -0.2}, p0{0.0, 0.8, 0.0, -0.5, 0.2, 0.6};
  nonsep::PhaseSpaceBatch x(3, 2);
  std::copy(q0.begin(), q0.end(), x.q().begin());
  std::copy(p0.begin(), p0.end(), x.p().begin());
  nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, 6);
  const double t_end = 100 * 2 * M_PI / B;
  const int steps = 40000;
  for (int s = 0; s < steps; ++s) gauss.step(model, x, t_end / steps);
  double error = 0.0;
  for (std::size_t b = 0; b < 2; ++b) {
    const auto exact = exact_state(B, w, q0.data() + 3 * b, p0.data() + 3 * b, t_end);
    for (std::size_t k = 0; k < 3; ++k)
      error = std::max({error, std::abs(x.q()[3 * b + k] - exact[k]), std::abs(x.p()[3 * b + k] - exact[3 + k])});
  }
  MESSAGE("magnetic_bottle (uniform field, omega 0.5), gauss 3 stages, dt = "
          << t_end / steps << ", 100 gyrations: largest error " << error);
  CHECK(error < 1e-12);
}

TEST_CASE("magnetic_bottle: gauss conserves the canonical angular momentum (a quadratic invariant) and H") {
  const PluginModel model = shipped("magnetic_bottle", {{"mirror", 0.5}});
  const std::vector<double> q{0.8, 0.0, 0.3}, p{0.0, 0.9, 0.7};
  // To t = 20, with the starting values and from Z = 0 (the same map up to round-off). Further on this orbit's close
  // approaches to the axis, where p_phi^2 / rho^2 stiffens the flow, amplify round-off: to t = 200 the largest error
  // of H was 1.2e-8 with the starting values and 1.6e-7 from Z = 0, with different end states: no bound to test.
  std::vector<std::vector<double>> ends;
  for (const bool extrapolate : {true, false}) {
    CAPTURE(extrapolate);
    auto x = nonsep::PhaseSpaceBatch::single(q, p);
    const auto momentum = [&] { return x.q()[0] * x.p()[1] - x.q()[1] * x.p()[0]; };
    nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
    const double l0 = momentum(), h0 = energy.evaluate_one(model, x);
    nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, 6, 100, extrapolate);
    double largest_l = 0.0, largest_h = 0.0;
    for (int s = 0; s < 2000; ++s) {
      gauss.step(model, x, 0.01);
      largest_l = std::max(largest_l, std::abs(momentum() - l0));
      largest_h = std::max(largest_h, std::abs(energy.evaluate_one(model, x) - h0) / h0);
    }
    MESSAGE("magnetic bottle, gauss 3 stages, dt 0.01 to t = 20: largest change of x p_y - y p_x "
            << largest_l << ", of H (relative) " << largest_h);
    CHECK(largest_l < 1e-14);
    CHECK(largest_h < 1e-12);  // 1.3e-14 measured: the scheme's accuracy at dt 0.01 (H is not quadratic)
    ends.push_back({x.q()[0], x.q()[1], x.q()[2], x.p()[0], x.p()[1], x.p()[2]});
  }
  for (std::size_t k = 0; k < 6; ++k) CHECK(std::abs(ends[0][k] - ends[1][k]) < 1e-10);
}

TEST_CASE("the shipped models given by H: grad_H and hvp_H agree with finite differences of their values") {
  for (const auto& name : {"henon_heiles", "magnetic_bottle"}) {
    CAPTURE(std::string(name));
    const PluginModel model = shipped(name);
    CHECK(model.plugin().general_hamiltonian());
    CHECK(model.plugin().abi_version() == NONSEP_PLUGIN_ABI_VERSION);
    CHECK(model.has_hamiltonian_hessian_products());
    const auto report = nonsep::check_hamiltonian_derivatives(model);
    INFO(report.summary());
    CHECK(report.passed());
    CHECK(report.skipped.empty());
    CHECK(report.comparisons == 16 * 2 * 2 * model.dimension());
  }
}

TEST_CASE("schwarzschild_charged: gauss keeps H on the mass shell and p_t, p_phi exactly") {
  const double E = 0.995, L = 4.6, beta = 8.9e-4, r = 11.0;
  const PluginModel model = shipped("schwarzschild_charged", {{"beta", beta}});
  // p_theta from H = -1/2 at theta = pi/2, p_r = 0.
  const double f = 1 - 2 / r, l = L - beta / 2 * r * r;
  const double p_theta = r * std::sqrt(-1 + E * E / f - l * l / (r * r));
  const std::vector<double> q{0.0, r, M_PI / 2, 0.0}, p{-E, 0.0, p_theta, L};
  auto x = nonsep::PhaseSpaceBatch::single(q, p);
  nonsep::EnergyEvaluator energy(nonsep::HamiltonianForm::TTV);
  const double h0 = energy.evaluate_one(model, x);
  CHECK(h0 == doctest::Approx(-0.5).epsilon(1e-14));
  nonsep::GaussLegendre gauss(nonsep::HamiltonianForm::TTV, 6);
  double largest_h = 0.0, r_min = r, r_max = r;
  for (int s = 0; s < 10000; ++s) {
    gauss.step(model, x, 1.0);
    largest_h = std::max(largest_h, std::abs(energy.evaluate_one(model, x) - h0));
    r_min = std::min(r_min, x.q()[1]);
    r_max = std::max(r_max, x.q()[1]);
  }
  MESSAGE("schwarzschild_charged, gauss 3 stages, dtau = 1 to tau = 10000: r in ["
          << r_min << ", " << r_max << "], largest |H - H0| " << largest_h);
  CHECK(largest_h < 1e-10);
  CHECK(x.p()[0] == -E);  // H does not depend on t or phi: their momenta are constant exactly
  CHECK(x.p()[3] == L);
  CHECK(r_min > 2.0);
}

}  // namespace test_general_hamiltonian
