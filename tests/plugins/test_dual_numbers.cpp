// The dual numbers behind the SDK's automatic differentiation: every operation and function gives the derivative
// that a finite difference gives, and the nested dual gives exact second derivatives.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <functional>
#include <string>

#include "nonsep/sdk/dual.hpp"
#include "nonsep/sdk/model_adapter.hpp"

using nonsep::sdk::Dual;

namespace {

template <class F>
double central_difference(const F& f, double x) {
  const double h = 1e-5;
  return (f(x + h) - f(x - h)) / (2.0 * h);
}

struct UnaryCase {
  const char* name;
  std::function<Dual<double, 1>(const Dual<double, 1>&)> on_dual;
  std::function<double(double)> on_double;
  double at;
};

}  // namespace

TEST_CASE("each function of dual.hpp has the derivative a finite difference gives") {
  using D = Dual<double, 1>;
  const UnaryCase cases[] = {
      {"sqrt", [](const D& x) { return sqrt(x); }, [](double x) { return std::sqrt(x); }, 1.7},
      {"cbrt", [](const D& x) { return cbrt(x); }, [](double x) { return std::cbrt(x); }, -2.3},
      {"exp", [](const D& x) { return exp(x); }, [](double x) { return std::exp(x); }, 0.4},
      {"log", [](const D& x) { return log(x); }, [](double x) { return std::log(x); }, 2.5},
      {"pow", [](const D& x) { return pow(x, 2.5); }, [](double x) { return std::pow(x, 2.5); }, 1.3},
      {"sin", [](const D& x) { return sin(x); }, [](double x) { return std::sin(x); }, 0.7},
      {"cos", [](const D& x) { return cos(x); }, [](double x) { return std::cos(x); }, 0.7},
      {"tan", [](const D& x) { return tan(x); }, [](double x) { return std::tan(x); }, 0.7},
      {"asin", [](const D& x) { return asin(x); }, [](double x) { return std::asin(x); }, 0.3},
      {"acos", [](const D& x) { return acos(x); }, [](double x) { return std::acos(x); }, 0.3},
      {"atan", [](const D& x) { return atan(x); }, [](double x) { return std::atan(x); }, 1.9},
      {"sinh", [](const D& x) { return sinh(x); }, [](double x) { return std::sinh(x); }, 0.8},
      {"cosh", [](const D& x) { return cosh(x); }, [](double x) { return std::cosh(x); }, 0.8},
      {"tanh", [](const D& x) { return tanh(x); }, [](double x) { return std::tanh(x); }, 0.8},
      {"asinh", [](const D& x) { return asinh(x); }, [](double x) { return std::asinh(x); }, -1.1},
      {"abs", [](const D& x) { return abs(x); }, [](double x) { return std::abs(x); }, -1.1},
      {"x / (1 - x)", [](const D& x) { return x / (1.0 - x); }, [](double x) { return x / (1.0 - x); }, 0.25},
      {"2 / x - x * 3 + 1", [](const D& x) { return 2.0 / x - x * 3.0 + 1.0; },
       [](double x) { return 2.0 / x - x * 3.0 + 1.0; }, 0.6},
  };
  for (const auto& c : cases) {
    CAPTURE(std::string(c.name));
    const D result = c.on_dual(D::variable(c.at, 0));
    CHECK(result.value == doctest::Approx(c.on_double(c.at)).epsilon(1e-15));
    CHECK(result.derivative[0] == doctest::Approx(central_difference(c.on_double, c.at)).epsilon(1e-8));
  }
}

TEST_CASE("abs at 0 has no derivative and says so with NaN") {
  const auto result = abs(Dual<double, 1>::variable(0.0, 0));
  CHECK(result.value == 0.0);
  CHECK(std::isnan(result.derivative[0]));
}

TEST_CASE("gradients and Hessians of a function of three variables are exact") {
  // f = x^2 y + sin(z) x / y; derivatives written out by hand.
  auto f = [](auto v) { return v[0] * v[0] * v[1] + sin(v[2]) * v[0] / v[1]; };
  const double x = 0.7, y = -1.3, z = 0.4;
  const double at[] = {x, y, z};
  double gradient[3], hessian[9];
  nonsep::sdk::detail::gradient_by_dual<3>(f, at, 3, gradient);
  nonsep::sdk::detail::hessian_by_dual<3>(f, at, 3, hessian);
  const double expected_gradient[] = {2 * x * y + std::sin(z) / y, x * x - std::sin(z) * x / (y * y),
                                      std::cos(z) * x / y};
  const double expected_hessian[] = {2 * y,
                                     2 * x - std::sin(z) / (y * y),
                                     std::cos(z) / y,
                                     2 * x - std::sin(z) / (y * y),
                                     2 * std::sin(z) * x / (y * y * y),
                                     -std::cos(z) * x / (y * y),
                                     std::cos(z) / y,
                                     -std::cos(z) * x / (y * y),
                                     -std::sin(z) * x / y};
  for (int i = 0; i < 3; ++i) CHECK(gradient[i] == doctest::Approx(expected_gradient[i]).epsilon(1e-14));
  for (int i = 0; i < 9; ++i) CHECK(hessian[i] == doctest::Approx(expected_hessian[i]).epsilon(1e-14));
}

TEST_CASE("a capacity larger than the dimension leaves the unused slots out of the result") {
  auto f = [](auto v) { return v[0] * v[1]; };
  const double at[] = {2.0, 5.0};
  double gradient[2], hessian[4];
  nonsep::sdk::detail::gradient_by_dual<16>(f, at, 2, gradient);
  nonsep::sdk::detail::hessian_by_dual<16>(f, at, 2, hessian);
  CHECK(gradient[0] == 5.0);
  CHECK(gradient[1] == 2.0);
  CHECK(hessian[0] == 0.0);
  CHECK(hessian[1] == 1.0);
  CHECK(hessian[2] == 1.0);
  CHECK(hessian[3] == 0.0);
}

TEST_CASE("comparisons look at values only") {
  const auto a = Dual<double, 2>::variable(1.0, 0), b = Dual<double, 2>::variable(2.0, 1);
  CHECK(a < b);
  CHECK(b > 1.5);
  CHECK(1.0 == a);
  CHECK(nonsep::sdk::value_of(Dual<Dual<double, 2>, 1>(3.5)) == 3.5);
}
