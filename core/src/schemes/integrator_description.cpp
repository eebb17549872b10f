#include "nonsep/core/schemes/integrator_description.hpp"

#include "nonsep/core/base/error.hpp"

namespace nonsep {

std::string chin_orders_text() { return "2/3, 4/3, 2, 8/3, 10/3, 4, ... (2j/3 for j = 1, 2, 3, ...)"; }

std::vector<Fraction> SchemeDescription::orders() const {
  if (!comparator_orders.empty()) return comparator_orders;
  std::vector<Fraction> orders;
  for (int j = 1; j <= highest_order_index; ++j) orders.push_back(Fraction(2 * j, 3));
  return orders;
}

int chin_order_index(const Fraction& order, int max_j, const std::string& what) {
  // order = a/b = 2j/3 in lowest terms: a = 2j, b = 3 when 3 does not divide j; a = 2j/3, b = 1 when it does. So
  // a is positive and even, b is 1 or 3, and j = 3a/2 or a/2. Divisions only: a may be as large as int64 allows.
  const std::int64_t a = order.numerator();
  const std::int64_t b = order.denominator();
  if (a <= 0 || a % 2 != 0 || (b != 1 && b != 3))
    throw InvalidArgument("the orders of " + what + " are " + chin_orders_text() + " (found " + order.to_string() +
                          ")");
  const std::int64_t half = a / 2;
  const bool beyond = b == 1 ? half > max_j / 3 : half > max_j;
  const std::int64_t j = beyond ? std::int64_t{max_j} + 1 : (b == 1 ? 3 * half : half);
  if (j > max_j)
    throw InvalidArgument("the highest order of " + what + " is " + Fraction(2 * max_j, 3).to_string() + " (found " +
                          order.to_string() + ")");
  return static_cast<int>(j);
}

}  // namespace nonsep
