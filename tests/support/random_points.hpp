#pragma once
// Reproducible test points: `size` numbers uniform in [-box, box] from the seed.
#include <cstddef>
#include <random>
#include <vector>

namespace nonsep::testing {

inline std::vector<double> random_points(std::size_t size, double box, unsigned seed) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> uniform(-box, box);
  std::vector<double> x(size);
  for (double& xi : x) xi = uniform(engine);
  return x;
}

}  // namespace nonsep::testing
