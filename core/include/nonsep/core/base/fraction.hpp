#pragma once
// Exact rational numbers for integrator orders: the methods of the paper have orders 2j/3 (2/3, 4/3, 2, ...),
// which a double cannot name exactly. Parsing accepts "4/3", "2", " 8 / 3 " and rejects anything else.
#include <cstdint>
#include <string>
#include <string_view>

namespace nonsep {

class Fraction {
 public:
  constexpr Fraction() = default;
  // Reduced to lowest terms with a positive denominator. Throws InvalidArgument if denominator == 0.
  Fraction(std::int64_t numerator, std::int64_t denominator = 1);

  // Parses "a/b" or "a" (optional sign, optional spaces around '/'). Throws InvalidArgument naming the text.
  static Fraction parse(std::string_view text);

  std::int64_t numerator() const { return numerator_; }
  std::int64_t denominator() const { return denominator_; }
  double value() const { return static_cast<double>(numerator_) / static_cast<double>(denominator_); }
  // "4/3", or "2" when the denominator is 1.
  std::string to_string() const;

  friend bool operator==(const Fraction&, const Fraction&) = default;

 private:
  std::int64_t numerator_ = 0;
  std::int64_t denominator_ = 1;
};

}  // namespace nonsep
