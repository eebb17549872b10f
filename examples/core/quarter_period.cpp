// The core library on its own: integrate the paper's 1D test H = (1 + p^2/2)^2 (1 + q^2) from (q, p) = (2, 0)
// to its quarter period with each scheme and print the error against the exact end point (0, -sqrt(2(sqrt5-1))).
// The quarter period is the one computed by tanh-sinh quadrature in reference/include/nonsep/reference/
// paper1d_exact.hpp (build/bin/nonsep_paper_reference prints it).
#include <cmath>
#include <cstdio>
#include <span>
#include <string>

#include "nonsep/core.hpp"

// T = p + p^3/6 and V = q^2/2 + q^4/12 (eq. algham), gradients only.
struct Paper1D {
  std::size_t dimension() const { return 1; }
  void grad_T(std::span<const double> p, std::span<double> out, std::size_t n) const {
    for (std::size_t b = 0; b < n; ++b) out[b] = 1.0 + 0.5 * p[b] * p[b];
  }
  void grad_V(std::span<const double> q, std::span<double> out, std::size_t n) const {
    for (std::size_t b = 0; b < n; ++b) out[b] = q[b] + q[b] * q[b] * q[b] / 3.0;
  }
};

int main() {
  const double quarter_period = 0.3863765573361232;
  const double p_exact = -std::sqrt(2.0 * (std::sqrt(5.0) - 1.0));
  const int steps = 400;
  std::printf("%-8s %-6s %10s %14s %14s\n", "scheme", "order", "grad evals", "q error", "p error");
  for (const char* scheme : {"basic", "triplet", "mpe"})
    for (int j = 1; j <= 4; ++j) {
      if (std::string(scheme) == "basic" && j > 1) break;
      nonsep::Integrator integrator(nonsep::IntegratorSpec{scheme, nonsep::ChinOptions{nonsep::Fraction(2 * j, 3)}});
      const double q0[] = {2.0}, p0[] = {0.0};
      auto x = nonsep::PhaseSpaceBatch::single(q0, p0);
      for (int s = 0; s < steps; ++s) integrator.step(Paper1D{}, x, quarter_period / steps);
      const auto evaluations = integrator.evaluations();
      std::printf("%-8s %-6s %10llu %14.3e %14.3e\n", scheme, integrator.describe().order.to_string().c_str(),
                  static_cast<unsigned long long>(evaluations.grad_T + evaluations.grad_V), x.q()[0],
                  x.p()[0] - p_exact);
    }
}
