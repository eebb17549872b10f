// The SDK's evaluation path (values, gradients, Hessians, directional third derivatives) does not touch the heap,
// with automatic differentiation or analytic derivatives:
// operator new is replaced for this test program and counts the allocations made while counting is on.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "paper1d/paper1d.hpp"
#include "radial/radial.hpp"

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

// GCC cannot see that these replacements pair malloc with free for every inlined new/delete expression.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t size) {
  if (counting.load()) ++allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

template <class Adapter>
long allocations_while_evaluating(const Adapter& adapter) {
  const std::size_t n = adapter.dimension(), count = 8;
  std::vector<double> x(n * count), gradient(n * count), hessian(n * n * count), values(count), u(n * count);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = 0.1 + 0.05 * static_cast<double>(k);
  for (std::size_t k = 0; k < u.size(); ++k) u[k] = 1.0 - 0.03 * static_cast<double>(k);
  allocations = 0;
  counting = true;
  adapter.grad_T(x, gradient, count);
  adapter.grad_V(x, gradient, count);
  adapter.hessian_T(x, hessian, count);
  adapter.hessian_V(x, hessian, count);
  adapter.value_T(x, values, count);
  adapter.value_V(x, values, count);
  adapter.d3T(x, u, gradient, count);
  adapter.d3V(x, u, gradient, count);
  counting = false;
  return allocations.load();
}

}  // namespace

TEST_CASE("evaluating gradients, Hessians, third derivatives and values allocates nothing") {
  using nonsep::sdk::Derivatives;
  using nonsep::sdk::ModelAdapter;
  CHECK(allocations_while_evaluating(ModelAdapter<Paper1D, Derivatives::automatic>()) == 0);
  CHECK(allocations_while_evaluating(ModelAdapter<Paper1D, Derivatives::preferred>()) == 0);
  CHECK(allocations_while_evaluating(ModelAdapter<Radial, Derivatives::automatic>::from_json(R"({"dimension": 5})")) ==
        0);
  CHECK(allocations_while_evaluating(ModelAdapter<Radial, Derivatives::preferred>::from_json(R"({"dimension": 16})")) ==
        0);
}

TEST_CASE("the allocation counter itself counts") {
  counting = true;
  allocations = 0;
  auto* p = new std::vector<double>(10);
  counting = false;
  delete p;
  CHECK(allocations.load() >= 1);
}
