// Exact references for the paper's 1D test H = (1 + p^2/2)^2 (1 + q^2) (eq. h1d), computed by the project:
// for each Figure 1 orbit (p0 = 0, q0 = 0.5, 1, 1.5, 2) the energy, the quarter period by tanh-sinh quadrature of
// the conserved energy, and p where the orbit crosses q = 0; and the exact level curves H = E for the plot.
//
//   nonsep_paper_reference [DIR]   writes DIR/exact_quarter_periods.csv and DIR/exact_level_curves.csv
//                                  (DIR defaults to the current folder) and prints the table.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "nonsep/reference/paper1d_exact.hpp"

int main(int argc, char** argv) {
  const std::filesystem::path directory = argc > 1 ? argv[1] : ".";
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  std::ofstream periods(directory / "exact_quarter_periods.csv");
  std::ofstream curves(directory / "exact_level_curves.csv");
  if (!periods || !curves) {
    std::cerr << "nonsep_paper_reference: cannot write into " << directory << "\n";
    return 2;
  }
  periods << "q0,energy,quarter_period,p_at_quarter\n";
  curves << "q0,energy,q,p\n";
  std::printf("%6s %8s %22s %22s\n", "q0", "energy", "quarter period", "p at q = 0");
  char line[160];
  for (const double q0 : {0.5, 1.0, 1.5, 2.0}) {
    const auto exact = nonsep::reference::paper1d_quarter(q0);
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g\n", q0, exact.energy, exact.period, exact.p_final);
    periods << line;
    std::printf("%6.2f %8.4f %22.16f %22.16f\n", q0, exact.energy, exact.period, exact.p_final);
    // The closed curve, sampled uniformly in the angle theta with q = q0 cos(theta) so the turning points are dense.
    const int samples = 720;
    for (int k = 0; k <= samples; ++k) {
      const double theta = 2.0 * M_PI * k / samples;
      const double q = q0 * std::cos(theta);
      const double p = (std::sin(theta) >= 0 ? 1.0 : -1.0) * nonsep::reference::paper1d_level_curve_p(q0, q);
      std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g\n", q0, exact.energy, q, p);
      curves << line;
    }
  }
  return periods.good() && curves.good() ? 0 : 1;
}
