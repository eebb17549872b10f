// nonsep_bench_ensemble_peer: one of Boost.Odeint's explicit adaptive methods on an ensemble of states, as a program
// of its own, so that bench/ensemble_work_precision.py times it as it times `nonsep run` (CPU time of the process).
//
//   nonsep_bench_ensemble_peer PROBLEM METHOD TOLERANCE T_END STATES.csv OUT.csv
//
// PROBLEM: paper1d (H = (1 + p^2/2)^2 (1 + q^2), the plugin paper1d) or paper2d (the plugin paper2d at its default
// coupling 0.2: H = grad T(p) . Hess V(q) grad T(p), T = p1 + p2 + (p1^3 + p2^3)/6, V = |q|^2/2 + |q|^4/12 +
// 0.2 q1^2 q2^2). METHOD: dopri5 (runge_kutta_dopri5), fehlberg78 (runge_kutta_fehlberg78), both under
// make_controlled, or bulirsch_stoer; absolute and relative tolerance TOLERANCE; integrate_adaptive from t = 0 to
// T_END (its last step lands on T_END), starting at dt = min(T_END / 100, 1e-3). STATES.csv and OUT.csv have nonsep's
// layout (header q0,...,p0,..., one state per row); OUT.csv holds the end points with 17 significant digits. Prints the
// evaluations of Hamilton's equations. Hamilton's equations are written by hand and checked against central
// differences of H at startup.
#include <algorithm>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

template <std::size_t N>
using State = std::array<double, 2 * N>;  // (q, p)

struct Paper1D {
  static constexpr std::size_t n = 1;
  static double H(const State<1>& x) {
    const double u = 1 + x[1] * x[1] / 2;
    return u * u * (1 + x[0] * x[0]);
  }
  static void equations(const State<1>& x, State<1>& dxdt) {
    const double q = x[0], p = x[1], u = 1 + p * p / 2;
    dxdt[0] = 2 * p * u * (1 + q * q);
    dxdt[1] = -2 * q * u * u;
  }
};

struct Paper2D {
  static constexpr std::size_t n = 2;
  static constexpr double c = 0.2;  // the plugin's default coupling
  // g = grad T(p), M = Hess V(q); H = g . M g.
  static void parts(const State<2>& x, double g[2], double m[3]) {
    const double q1 = x[0], q2 = x[1], radial = 1 + (q1 * q1 + q2 * q2) / 3;
    g[0] = 1 + x[2] * x[2] / 2;
    g[1] = 1 + x[3] * x[3] / 2;
    m[0] = radial + 2.0 / 3 * q1 * q1 + 2 * c * q2 * q2;
    m[1] = (2.0 / 3 + 4 * c) * q1 * q2;
    m[2] = radial + 2.0 / 3 * q2 * q2 + 2 * c * q1 * q1;
  }
  static double H(const State<2>& x) {
    double g[2], m[3];
    parts(x, g, m);
    return g[0] * (m[0] * g[0] + m[1] * g[1]) + g[1] * (m[1] * g[0] + m[2] * g[1]);
  }
  static void equations(const State<2>& x, State<2>& dxdt) {
    double g[2], m[3];
    parts(x, g, m);
    const double q1 = x[0], q2 = x[1], k = 2.0 / 3 + 4 * c;
    // dH/dp_i = 2 (M g)_i p_i; dH/dq_j = g . (dM/dq_j) g.
    dxdt[0] = 2 * (m[0] * g[0] + m[1] * g[1]) * x[2];
    dxdt[1] = 2 * (m[1] * g[0] + m[2] * g[1]) * x[3];
    dxdt[2] = -(g[0] * g[0] * 2 * q1 + 2 * g[0] * g[1] * k * q2 + g[1] * g[1] * k * q1);
    dxdt[3] = -(g[0] * g[0] * k * q2 + 2 * g[0] * g[1] * k * q1 + g[1] * g[1] * 2 * q2);
  }
};

// Hamilton's equations against central differences of H at a few points (relative 1e-7).
template <class P>
void check_equations() {
  constexpr std::size_t n = P::n;
  for (const double scale : {0.3, 0.9, 1.7}) {
    State<n> x{};
    for (std::size_t i = 0; i < 2 * n; ++i) x[i] = scale * (i % 2 == 0 ? 1.0 : -0.7) + 0.1 * static_cast<double>(i);
    State<n> dxdt{};
    P::equations(x, dxdt);
    for (std::size_t i = 0; i < 2 * n; ++i) {
      const double h = 1e-6;
      State<n> plus = x, minus = x;
      plus[i] += h;
      minus[i] -= h;
      const double derivative = (P::H(plus) - P::H(minus)) / (2 * h);
      // dq/dt = dH/dp, dp/dt = -dH/dq.
      const double expected = i < n ? -derivative : derivative;
      const double got = i < n ? dxdt[i + n] : dxdt[i - n];
      if (std::abs(got - expected) > 1e-7 * std::max(1.0, std::abs(expected)))
        throw std::logic_error("Hamilton's equations disagree with central differences of H");
    }
  }
}

template <std::size_t N>
std::vector<State<N>> read_states(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::string line;
  std::getline(in, line);  // the header
  std::vector<State<N>> states;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::istringstream row(line);
    State<N> x{};
    for (std::size_t i = 0; i < 2 * N; ++i) {
      std::string cell;
      if (!std::getline(row, cell, ',')) throw std::runtime_error(path + ": a row has fewer than 2n numbers");
      x[i] = std::stod(cell);
    }
    states.push_back(x);
  }
  return states;
}

template <std::size_t N>
void write_states(const std::string& path, const std::vector<State<N>>& states) {
  std::ofstream out(path);
  for (std::size_t i = 0; i < 2 * N; ++i) out << (i ? "," : "") << (i < N ? "q" : "p") << (i % N);
  out << '\n';
  char number[32];
  for (const auto& x : states) {
    for (std::size_t i = 0; i < 2 * N; ++i) {
      std::snprintf(number, sizeof number, "%.17g", x[i]);
      out << (i ? "," : "") << number;
    }
    out << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

// GCC warns that Odeint's controlled_runge_kutta copies the fehlberg78 stepper's scratch arrays before they are
// written (std::array members, default-initialised); they are written before they are read.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
template <class P>
std::uint64_t integrate(const std::string& method, double tolerance, double t_end, std::vector<State<P::n>>& states) {
  namespace odeint = boost::numeric::odeint;
  using S = State<P::n>;
  // A first step that overflows gives a NaN error estimate, which the controller accepts (paper2d from p = (0.5, 2)
  // with dt = 1): start small and let the controller grow the step (by up to 5x a step).
  const double initial_dt = std::min(t_end / 100, 1e-3);
  std::uint64_t evaluations = 0;
  const auto system = [&evaluations](const S& x, S& dxdt, double) {
    ++evaluations;
    P::equations(x, dxdt);
  };
  for (S& x : states) {
    if (method == "dopri5")
      odeint::integrate_adaptive(odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<S>()), system,
                                 x, 0.0, t_end, initial_dt);
    else if (method == "fehlberg78")
      odeint::integrate_adaptive(odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_fehlberg78<S>()),
                                 system, x, 0.0, t_end, initial_dt);
    else if (method == "bulirsch_stoer")
      odeint::integrate_adaptive(odeint::bulirsch_stoer<S>(tolerance, tolerance), system, x, 0.0, t_end, initial_dt);
    else
      throw std::invalid_argument("unknown method \"" + method + "\" (dopri5, fehlberg78, bulirsch_stoer)");
  }
  return evaluations;
}
#pragma GCC diagnostic pop

template <class P>
void run(const std::string& method, double tolerance, double t_end, const std::string& in, const std::string& out) {
  check_equations<P>();
  auto states = read_states<P::n>(in);
  const std::uint64_t evaluations = integrate<P>(method, tolerance, t_end, states);
  write_states<P::n>(out, states);
  std::cout << evaluations << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::cerr << "usage: nonsep_bench_ensemble_peer paper1d|paper2d dopri5|fehlberg78|bulirsch_stoer TOLERANCE T_END "
                 "STATES.csv OUT.csv\n";
    return 2;
  }
  try {
    const std::string problem = argv[1], method = argv[2];
    const double tolerance = std::stod(argv[3]), t_end = std::stod(argv[4]);
    if (problem == "paper1d")
      run<Paper1D>(method, tolerance, t_end, argv[5], argv[6]);
    else if (problem == "paper2d")
      run<Paper2D>(method, tolerance, t_end, argv[5], argv[6]);
    else
      throw std::invalid_argument("unknown problem \"" + problem + "\" (paper1d, paper2d)");
  } catch (const std::exception& error) {
    std::cerr << "nonsep_bench_ensemble_peer: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
