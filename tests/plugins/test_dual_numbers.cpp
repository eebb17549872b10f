// The dual numbers behind the SDK's automatic differentiation: every operation and function gives the derivative
// that a finite difference gives, and the nested dual gives exact second derivatives.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "nonsep/sdk/dual.hpp"
#include "nonsep/sdk/model_adapter.hpp"
#include "support/finite_difference.hpp"

namespace test_dual_numbers {

using nonsep::sdk::Dual;

namespace {

using nonsep::testing::central_difference;
using nonsep::testing::central_difference_along;

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
      {"acosh", [](const D& x) { return acosh(x); }, [](double x) { return std::acosh(x); }, 1.6},
      {"atanh", [](const D& x) { return atanh(x); }, [](double x) { return std::atanh(x); }, -0.45},
      {"expm1", [](const D& x) { return expm1(x); }, [](double x) { return std::expm1(x); }, -0.3},
      {"log1p", [](const D& x) { return log1p(x); }, [](double x) { return std::log1p(x); }, 0.35},
      {"erf", [](const D& x) { return erf(x); }, [](double x) { return std::erf(x); }, 0.8},
      {"pow(2.5, x)", [](const D& x) { return pow(2.5, x); }, [](double x) { return std::pow(2.5, x); }, -0.7},
      {"pow(x, x)", [](const D& x) { return pow(x, x); }, [](double x) { return std::pow(x, x); }, 1.4},
      {"min(x, 0.5)", [](const D& x) { return min(x, 0.5); }, [](double x) { return std::min(x, 0.5); }, 0.3},
      {"max(x, 0.5)", [](const D& x) { return max(x, 0.5); }, [](double x) { return std::max(x, 0.5); }, 0.3},
      {"atan2(x, 0.4)", [](const D& x) { return atan2(x, 0.4); }, [](double x) { return std::atan2(x, 0.4); }, -1.2},
      {"hypot(0.4, x)", [](const D& x) { return hypot(0.4, x); }, [](double x) { return std::hypot(0.4, x); }, -1.2},
      {"x / (1 - x)", [](const D& x) { return x / (1.0 - x); }, [](double x) { return x / (1.0 - x); }, 0.25},
      {"2 / x - x * 3 + 1", [](const D& x) { return 2.0 / x - x * 3.0 + 1.0; },
       [](double x) { return 2.0 / x - x * 3.0 + 1.0; }, 0.6},
  };
  for (const auto& c : cases) {
    CAPTURE(std::string(c.name));
    const D result = c.on_dual(D::variable(c.at, 0));
    CHECK(result.value == doctest::Approx(c.on_double(c.at)).epsilon(1e-15));
    CHECK(result.derivative[0] == doctest::Approx(central_difference(c.on_double, c.at, 1e-5)).epsilon(1e-8));
  }
}

TEST_CASE("abs at 0 has no derivative and says so with NaN") {
  const auto result = abs(Dual<double, 1>::variable(0.0, 0));
  CHECK(result.value == 0.0);
  CHECK(std::isnan(result.derivative[0]));
}

namespace {
// T = acosh(p0) + atanh(p1): outside their domains (acosh below 1, atanh outside [-1, 1]) both are NaN, though
// the formulas of their derivatives are finite there.
struct OutsideDomains {
  static constexpr std::size_t dimension = 2;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    return acosh(p[0]) + atanh(p[1]);
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    return q[0] * q[0] + q[1] * q[1];
  }
};
}  // namespace

TEST_CASE("a gradient by automatic differentiation is NaN where T is outside its domain, though it skips T's value") {
  const nonsep::sdk::ModelAdapter<OutsideDomains> model;
  double gradient[2];
  const double outside[] = {-2.0, 2.0};  // acosh(-2) and atanh(2) are NaN; 1/sqrt(x^2 - 1) and 1/(1 - x^2) are not
  model.grad_T(outside, gradient, 1);
  CHECK(std::isnan(gradient[0]));
  CHECK(std::isnan(gradient[1]));
  const double inside[] = {2.0, 0.5};
  model.grad_T(inside, gradient, 1);
  CHECK(gradient[0] == doctest::Approx(1.0 / std::sqrt(3.0)).epsilon(1e-15));
  CHECK(gradient[1] == doctest::Approx(1.0 / 0.75).epsilon(1e-15));
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

namespace {

// A function of two variables, written once for any scalar (double and every nesting of duals).
struct BinaryCase {
  const char* name;
  std::function<double(nonsep::sdk::Vector<double>)> on_double;
  std::function<nonsep::sdk::GradientDual<2>(nonsep::sdk::Vector<nonsep::sdk::GradientDual<2>>)> gradient;
  std::function<nonsep::sdk::HessianDual<2>(nonsep::sdk::Vector<nonsep::sdk::HessianDual<2>>)> hessian;
  std::function<nonsep::sdk::ThirdDerivativeDual<2>(nonsep::sdk::Vector<nonsep::sdk::ThirdDerivativeDual<2>>)> third;
  std::array<double, 2> at;
};

// The using-directive gives the double versions (nonsep::sdk's using-declarations of std's); ADL the dual ones.
#define NONSEP_TEST_BINARY(name, expression, x, y) \
  BinaryCase {                                     \
    name,                                          \
        [](auto v) {                               \
          using namespace nonsep::sdk;             \
          return expression;                       \
        },                                         \
        [](auto v) {                               \
          using namespace nonsep::sdk;             \
          return expression;                       \
        },                                         \
        [](auto v) {                               \
          using namespace nonsep::sdk;             \
          return expression;                       \
        },                                         \
        [](auto v) {                               \
          using namespace nonsep::sdk;             \
          return expression;                       \
        },                                         \
    {                                              \
      x, y                                         \
    }                                              \
  }

// Central difference of g (a vector of `size` numbers at a 2-point) along e_k, component i.
template <class G>
double difference(const G& g, std::array<double, 2> at, std::size_t k, std::size_t i, std::size_t size) {
  const auto values = [&](const std::vector<double>& point) {
    std::vector<double> out(size);
    g(point.data(), out.data());
    return out;
  };
  return central_difference_along(values, {at[0], at[1]}, k, 1e-5)[i];
}

}  // namespace

TEST_CASE(
    "two-argument functions and pow with a variable exponent: gradients, Hessians and third derivatives "
    "of every nesting agree with finite differences") {
  using nonsep::sdk::detail::directional_third_by_dual;
  using nonsep::sdk::detail::gradient_by_dual;
  using nonsep::sdk::detail::hessian_by_dual;
  const BinaryCase cases[] = {
      NONSEP_TEST_BINARY("atan2", atan2(v[0], v[1]), 0.7, -1.3),
      NONSEP_TEST_BINARY("hypot", hypot(v[0], v[1]), 0.7, -1.3),
      NONSEP_TEST_BINARY("pow(x, y)", pow(v[0], v[1]), 1.7, -0.6),
      NONSEP_TEST_BINARY("pow(x, y) x y", pow(v[0] * v[1] + 2.0, v[1] * 0.5), 0.4, 1.3),
      NONSEP_TEST_BINARY("min", min(v[0], v[1]) * v[1], 0.7, -1.3),
      NONSEP_TEST_BINARY("max", max(v[0] * v[0], v[1]) * v[0], 0.7, -1.3),
      NONSEP_TEST_BINARY("erf expm1 log1p", erf(v[0]) * expm1(v[1]) + log1p(v[0] * v[1]), 0.3, 0.8),
      NONSEP_TEST_BINARY("acosh atanh", acosh(1.5 + v[0] * v[0]) * atanh(v[1] / 2.0), -0.4, 0.9),
  };
  const double u[] = {0.8, -0.35};
  for (const auto& c : cases) {
    CAPTURE(std::string(c.name));
    double gradient[2], hessian[4], third[2];
    const double value = gradient_by_dual<2>(c.gradient, c.at.data(), 2, gradient);
    CHECK(value == doctest::Approx(c.on_double(c.at)).epsilon(1e-15));
    CHECK(hessian_by_dual<2>(c.hessian, c.at.data(), 2, hessian) == doctest::Approx(value).epsilon(1e-15));
    CHECK(directional_third_by_dual<2>(c.third, c.at.data(), u, 2, third) == doctest::Approx(value).epsilon(1e-15));
    const auto values = [&](const double* x, double* out) { out[0] = c.on_double(nonsep::sdk::Vector<double>(x, 2)); };
    const auto gradients = [&](const double* x, double* out) { gradient_by_dual<2>(c.gradient, x, 2, out); };
    const auto quadratic_form = [&](const double* x, double* out) {
      double h[4];
      hessian_by_dual<2>(c.hessian, x, 2, h);
      out[0] = u[0] * u[0] * h[0] + u[0] * u[1] * (h[1] + h[2]) + u[1] * u[1] * h[3];
    };
    for (std::size_t k = 0; k < 2; ++k) {
      CHECK(gradient[k] == doctest::Approx(difference(values, c.at, k, 0, 1)).epsilon(1e-8));
      for (std::size_t i = 0; i < 2; ++i)
        CHECK(hessian[i * 2 + k] == doctest::Approx(difference(gradients, c.at, k, i, 2)).epsilon(1e-8));
      CHECK(third[k] == doctest::Approx(difference(quadratic_form, c.at, k, 0, 1)).epsilon(1e-7));
    }
  }
}

TEST_CASE("pow(x, y) at x = 0 and x < 0 has derivative 0 in y, so pow(x, S(3)) works for negative x") {
  using D = Dual<double, 2>;
  const D x = D::variable(-2.0, 0), y = D(3.0);
  const D r = pow(x, y);
  CHECK(r.value == -8.0);
  CHECK(r.derivative[0] == 12.0);
  CHECK(r.derivative[1] == 0.0);
  const D zero = pow(D::variable(0.0, 0), D::variable(2.0, 1));
  CHECK(zero.value == 0.0);
  CHECK(zero.derivative[0] == 0.0);
  CHECK(zero.derivative[1] == 0.0);
}

TEST_CASE("directional third derivatives of a function of three variables are exact") {
  // f = x^2 y z + exp(y) z^3: T_ijk written out; out_k = sum_ij f_ijk u_i u_j.
  auto f = [](auto v) { return v[0] * v[0] * v[1] * v[2] + exp(v[1]) * v[2] * v[2] * v[2]; };
  const double x = 0.7, y = -0.4, z = 1.1, at[] = {x, y, z}, u[] = {0.5, -1.2, 0.9};
  double third[3];
  nonsep::sdk::detail::directional_third_by_dual<5>(f, at, u, 3, third);
  // Nonzero third derivatives: f_xxy = 2z, f_xxz = 2y, f_xyz = 2x, f_yyy = e^y z^3, f_yyz = 3 e^y z^2,
  // f_yzz = 6 e^y z, f_zzz = 6 e^y.
  const double e = std::exp(y);
  const double f_xxy = 2 * z, f_xxz = 2 * y, f_xyz = 2 * x, f_yyy = e * z * z * z, f_yyz = 3 * e * z * z,
               f_yzz = 6 * e * z, f_zzz = 6 * e;
  const double ux = u[0], uy = u[1], uz = u[2];
  const double expected[] = {
      2 * f_xxy * ux * uy + 2 * f_xxz * ux * uz + 2 * f_xyz * uy * uz,
      f_xxy * ux * ux + 2 * f_xyz * ux * uz + f_yyy * uy * uy + 2 * f_yyz * uy * uz + f_yzz * uz * uz,
      f_xxz * ux * ux + 2 * f_xyz * ux * uy + f_yyz * uy * uy + 2 * f_yzz * uy * uz + f_zzz * uz * uz};
  for (int k = 0; k < 3; ++k) CHECK(third[k] == doctest::Approx(expected[k]).epsilon(1e-14));
}

}  // namespace test_dual_numbers
