#pragma once
// The tests' one finite-difference rule: central differences, of a scalar function and of a function returning
// several numbers. The Jacobians of phase-space maps built on it are in support/phase_space_jacobian.hpp. (Plugins
// are checked by the SDK's own 5-point rule, plugins/sdk/include/nonsep/derivative_checker.hpp, which is part of
// the product.)
#include <cstddef>
#include <vector>

namespace nonsep::testing {

// (f(x + h) - f(x - h)) / 2h.
template <class F>
double central_difference(const F& f, double x, double h) {
  return (f(x + h) - f(x - h)) / (2.0 * h);
}

// The central difference of f (std::vector<double> -> std::vector<double>) along variable k of z, step h: one
// number per output of f.
template <class F>
std::vector<double> central_difference_along(const F& f, const std::vector<double>& z, std::size_t k, double h) {
  std::vector<double> plus = z, minus = z;
  plus[k] += h;
  minus[k] -= h;
  const std::vector<double> a = f(plus), b = f(minus);
  std::vector<double> difference(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) difference[i] = (a[i] - b[i]) / (2.0 * h);
  return difference;
}

}  // namespace nonsep::testing
