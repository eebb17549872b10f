// The models compiled into the tests have hand-written derivatives; check them against central differences.
#include <doctest/doctest.h>

#include <functional>
#include <vector>

#include "support/models.hpp"
#include "support/nan_aware.hpp"

namespace {
// Max |analytic - central difference of f| over the components, where f maps a point to a vector.
template <class F, class G>
double derivative_error(F f, G derivative, std::vector<double> x, std::size_t out_size) {
  const double h = 1e-6;
  std::vector<double> analytic(out_size * x.size()), plus(out_size), minus(out_size);
  derivative(x, analytic);
  double worst = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    auto xp = x, xm = x;
    xp[k] += h;
    xm[k] -= h;
    f(xp, plus);
    f(xm, minus);
    for (std::size_t i = 0; i < out_size; ++i)
      worst = nonsep::testing::max_or_nan(worst, std::abs((plus[i] - minus[i]) / (2 * h) - analytic[i * x.size() + k]));
  }
  return worst;
}
}  // namespace

TEST_CASE("test models: Hessians are the derivatives of the gradients") {
  using V = std::vector<double>;
  nonsep::testing::Coupled2D m2;
  for (const V& x : {V{0.3, -0.2}, V{-1.1, 0.7}}) {
    CHECK(derivative_error([&](const V& a, V& o) { m2.grad_T(a, o, 1); }, [&](const V& a, V& o) { m2.hessian_T(a, o, 1); }, x, 2) < 1e-8);
    CHECK(derivative_error([&](const V& a, V& o) { m2.grad_V(a, o, 1); }, [&](const V& a, V& o) { m2.hessian_V(a, o, 1); }, x, 2) < 1e-8);
  }
  nonsep::testing::Paper1D m1;
  CHECK(derivative_error([&](const V& a, V& o) { m1.grad_T(a, o, 1); }, [&](const V& a, V& o) { m1.hessian_T(a, o, 1); }, V{0.8}, 1) < 1e-8);
  CHECK(derivative_error([&](const V& a, V& o) { m1.grad_V(a, o, 1); }, [&](const V& a, V& o) { m1.hessian_V(a, o, 1); }, V{-1.4}, 1) < 1e-8);
  // The gradients are those of T and V themselves (the potentials are written out here once more).
  auto T2 = [](const V& p, V& o) { const double r2 = p[0] * p[0] + p[1] * p[1]; o[0] = p[0] + p[1] / 2 + r2 * r2 / 24 + p[0] * p[1] * p[1] / 6; };
  auto V2 = [](const V& q, V& o) { o[0] = (q[0] * q[0] + q[1] * q[1]) / 2 + q[0] * q[0] * q[1] / 3 + std::pow(q[1], 4) / 12; };
  CHECK(derivative_error(T2, [&](const V& a, V& o) { m2.grad_T(a, o, 1); }, V{0.4, -0.9}, 1) < 1e-8);
  CHECK(derivative_error(V2, [&](const V& a, V& o) { m2.grad_V(a, o, 1); }, V{0.4, -0.9}, 1) < 1e-8);
}
