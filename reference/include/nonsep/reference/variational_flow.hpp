#pragma once
// An independent reference for Lyapunov exponents: the variational equations of a Hamiltonian H(x),
// x = (q_1 .. q_n, p_1 .. p_n), N = 2n,
//   dx/dt = J grad H(x),      d delta/dt = J Hess H(x) delta,      J = [[0, I], [-I, 0]],
// integrated by Boost.Odeint's controlled Runge-Kutta-Fehlberg 7(8) at tight tolerance. Nothing of the splitting
// is used: the derivatives of H come from forward-mode automatic differentiation (the SDK's dual numbers,
// Dual<Dual<double, N>, 1>, N passes for the Hessian) of a closed-form H written for any scalar type, so the
// reference checks the tangent maps of the integrators (which use grad T, Hess T, grad V, Hess V of the
// splitting) against the flow of the Hamiltonian they approximate.
//
// Hamiltonian: any object with `template <class S> S hamiltonian(const S* x) const` (tests/support/models.hpp).
// The finite-time exponent of delta after a time t is ln(|delta(t)| / |delta(0)|) / t; delta is renormalised to
// unit length at every sampled time and at least every `renormalize_interval`, the logarithms of the lengths
// being summed, so long runs do not overflow.
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstddef>
#include <nonsep/sdk/dual.hpp>
#include <vector>

namespace nonsep::reference {

template <std::size_t N, class Hamiltonian>
class VariationalFlow {
  static_assert(N % 2 == 0, "N = 2n: the phase-space dimension");
  static constexpr std::size_t n = N / 2;

 public:
  using Point = std::array<double, N>;
  using Matrix = std::array<double, N * N>;  // row-major

  explicit VariationalFlow(Hamiltonian hamiltonian, double tolerance = 1e-13)
      : hamiltonian_(std::move(hamiltonian)), tolerance_(tolerance) {}

  double energy(const Point& x) const { return hamiltonian_.hamiltonian(x.data()); }

  // grad H and Hess H at x by automatic differentiation.
  void derivatives(const Point& x, Point& gradient, Matrix& hessian) const {
    using Inner = nonsep::sdk::Dual<double, N>;
    using Outer = nonsep::sdk::Dual<Inner, 1>;
    std::array<Outer, N> variables;
    for (std::size_t column = 0; column < N; ++column) {
      for (std::size_t i = 0; i < N; ++i) {
        variables[i].value = Inner::variable(x[i], i);
        variables[i].derivative[0] = Inner(i == column ? 1.0 : 0.0);
      }
      const Outer h = hamiltonian_.hamiltonian(variables.data());
      for (std::size_t i = 0; i < N; ++i) hessian[i * N + column] = h.derivative[0].derivative[i];
      if (column == 0)
        for (std::size_t i = 0; i < N; ++i) gradient[i] = h.value.derivative[i];
    }
  }

  // The largest finite-time exponent of the orbit of x along delta, at each of `times` (ascending, positive):
  // entry i is ln(|delta(times[i])| / |delta(0)|) / times[i]. x and delta are advanced to the last time.
  std::vector<double> finite_time_exponents(Point& x, Point& delta, const std::vector<double>& times,
                                            double renormalize_interval = 1.0) const {
    namespace odeint = boost::numeric::odeint;
    using State = std::vector<double>;  // (x, delta)
    auto stepper = odeint::make_controlled(tolerance_, tolerance_, odeint::runge_kutta_fehlberg78<State>());
    auto rhs = [this](const State& s, State& d, double) {
      Point point{}, gradient{}, tangent_force{};
      Matrix hessian{};
      std::copy_n(s.begin(), N, point.begin());
      derivatives(point, gradient, hessian);
      for (std::size_t r = 0; r < N; ++r) {
        double sum = 0.0;
        for (std::size_t c = 0; c < N; ++c) sum += hessian[r * N + c] * s[N + c];
        tangent_force[r] = sum;
      }
      for (std::size_t i = 0; i < n; ++i) {
        d[i] = gradient[n + i];
        d[n + i] = -gradient[i];
        d[N + i] = tangent_force[n + i];
        d[N + n + i] = -tangent_force[i];
      }
    };
    State s(2 * N);
    std::copy(x.begin(), x.end(), s.begin());
    std::copy(delta.begin(), delta.end(), s.begin() + N);
    double log_growth = 0.0, t = 0.0;
    normalize(s);
    std::vector<double> exponents;
    for (const double until : times) {
      while (t < until) {
        const double next = std::min(until, t + renormalize_interval);
        odeint::integrate_adaptive(stepper, rhs, s, t, next, (next - t) / 16);
        t = next;
        log_growth += std::log(norm(s));
        normalize(s);
      }
      exponents.push_back(log_growth / until);
    }
    std::copy_n(s.begin(), N, x.begin());
    std::copy_n(s.begin() + N, N, delta.begin());
    return exponents;
  }

 private:
  template <class State>
  static double norm(const State& s) {
    double sum = 0.0;
    for (std::size_t i = N; i < 2 * N; ++i) sum += s[i] * s[i];
    return std::sqrt(sum);
  }
  template <class State>
  static void normalize(State& s) {
    const double inverse = 1.0 / norm(s);
    for (std::size_t i = N; i < 2 * N; ++i) s[i] *= inverse;
  }

  Hamiltonian hamiltonian_;
  double tolerance_;
};

}  // namespace nonsep::reference
