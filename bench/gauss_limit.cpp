// nonsep_bench_gauss_limit: the limit nonsep's Gauss-Legendre path is measured against (bench/gauss_limit.py):
// Gauss-Legendre with S stages on paper1d (TTV: H = (1 + p^2/2)^2 (1 + q^2)) written out by hand, one state at a
// time, grad H in closed form and inline, with what core/include/nonsep/core/schemes/gauss_legendre.hpp does: the
// same tableau (GaussLegendreTableau: hb_i = fl(dt b_i), mu, nu), the starting values from the last step's L
// extrapolated by nu, the same fixed-point iteration and stopping rule (relative change <= eps, or no longer
// decreasing and <= 64 eps), and the compensated sum z + sum_i L_i.
//
//   nonsep_bench_gauss_limit STAGES DT STEPS STATES.csv OUT.csv
//
// STATES.csv and OUT.csv have nonsep's layout (header q0,p0). Prints the iterations per state and step and the
// seconds of the stepping loop. The end states agree with nonsep's to round-off, not bit for bit: grad H is summed in
// another order than the host composes it from the plugin's derivatives.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/core/schemes/gauss_legendre.hpp"

namespace {

struct State {
  double q = 0.0, p = 0.0;
};

template <int S>
struct Limit {
  double hb[S], mu[S * S], nu[S * S];

  Limit(const nonsep::GaussLegendreTableau& tableau, double dt) {
    for (int i = 0; i < S; ++i) hb[i] = dt * tableau.b[static_cast<std::size_t>(i)];
    for (int k = 0; k < S * S; ++k) {
      mu[k] = tableau.mu[static_cast<std::size_t>(k)];
      nu[k] = tableau.nu[static_cast<std::size_t>(k)];
    }
  }

  // `steps` steps of one state; returns the iterations.
  std::uint64_t run(State& z, std::uint64_t steps) const {
    const double eps = std::numeric_limits<double>::epsilon();
    double Lq[S] = {}, Lp[S] = {}, error_q = 0.0, error_p = 0.0;
    std::uint64_t iterations = 0;
    for (std::uint64_t step = 0; step < steps; ++step) {
      double Zq[S], Zp[S];
      for (int i = 0; i < S; ++i) {
        double sq = 0.0, sp = 0.0;
        for (int j = 0; j < S; ++j) {
          sq += nu[i * S + j] * Lq[j];
          sp += nu[i * S + j] * Lp[j];
        }
        Zq[i] = step == 0 ? 0.0 : sq;
        Zp[i] = step == 0 ? 0.0 : sp;
      }
      double last = std::numeric_limits<double>::infinity();
      for (int m = 0; m < 100; ++m) {
        ++iterations;
        for (int i = 0; i < S; ++i) {
          const double q = z.q + Zq[i], p = z.p + Zp[i], u = 1.0 + 0.5 * p * p;
          Lq[i] = hb[i] * (2.0 * p * u * (1.0 + q * q));  // dH/dp
          Lp[i] = hb[i] * -(2.0 * q * u * u);             // -dH/dq
        }
        double change = 0.0, scale = std::max(std::abs(z.q), std::abs(z.p));
        for (int i = 0; i < S; ++i) {
          double sq = 0.0, sp = 0.0;
          for (int j = 0; j < S; ++j) {
            sq += mu[i * S + j] * Lq[j];
            sp += mu[i * S + j] * Lp[j];
          }
          change = std::max(change, std::max(std::abs(sq - Zq[i]), std::abs(sp - Zp[i])));
          scale = std::max(scale, std::max(std::abs(sq), std::abs(sp)));
          Zq[i] = sq;
          Zp[i] = sp;
        }
        const double relative = scale > 0.0 ? change / scale : 0.0;
        if (relative <= eps || (relative >= last && relative <= 64 * eps)) break;
        last = relative;
      }
      double sum_q = 0.0, sum_p = 0.0;
      for (int i = 0; i < S; ++i) {
        sum_q += Lq[i];
        sum_p += Lp[i];
      }
      const auto add = [](double& x, double increment, double& error) {
        increment += error;
        const double sum = x + increment, part = sum - x;
        error = (x - (sum - part)) + (increment - part);
        x = sum;
      };
      add(z.q, sum_q, error_q);
      add(z.p, sum_p, error_p);
    }
    return iterations;
  }
};

template <int S>
std::uint64_t run_all(double dt, std::uint64_t steps, std::vector<State>& states) {
  const Limit<S> limit(nonsep::GaussLegendreTableau::for_stages(S), dt);
  std::uint64_t iterations = 0;
  for (State& z : states) iterations += limit.run(z, steps);
  return iterations;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::cerr << "usage: nonsep_bench_gauss_limit STAGES(1-4) DT STEPS STATES.csv OUT.csv\n";
    return 2;
  }
  try {
    const int stages = std::stoi(argv[1]);
    const double dt = std::stod(argv[2]);
    const auto steps = static_cast<std::uint64_t>(std::stoull(argv[3]));
    std::ifstream in(argv[4]);
    if (!in) throw std::runtime_error(std::string("cannot read ") + argv[4]);
    std::string line;
    std::getline(in, line);
    std::vector<State> states;
    while (std::getline(in, line)) {
      if (line.empty()) continue;
      std::istringstream row(line);
      std::string q, p;
      std::getline(row, q, ',');
      std::getline(row, p, ',');
      states.push_back({std::stod(q), std::stod(p)});
    }
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t iterations = 0;
    switch (stages) {
      case 1:
        iterations = run_all<1>(dt, steps, states);
        break;
      case 2:
        iterations = run_all<2>(dt, steps, states);
        break;
      case 3:
        iterations = run_all<3>(dt, steps, states);
        break;
      case 4:
        iterations = run_all<4>(dt, steps, states);
        break;
      default:
        throw std::invalid_argument("1 to 4 stages");
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::ofstream out(argv[5]);
    out << "q0,p0\n";
    char number[64];
    for (const State& z : states) {
      std::snprintf(number, sizeof number, "%.17g,%.17g\n", z.q, z.p);
      out << number;
    }
    std::printf("%.6f %.6f\n", static_cast<double>(iterations) / static_cast<double>(states.size() * steps), seconds);
  } catch (const std::exception& error) {
    std::cerr << "nonsep_bench_gauss_limit: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
