#include "nonsep/core/base/fraction.hpp"

#include <charconv>
#include <limits>
#include <numeric>

#include "nonsep/core/base/error.hpp"

namespace nonsep {

Fraction::Fraction(std::int64_t numerator, std::int64_t denominator) {
  if (denominator == 0) throw InvalidArgument("a fraction cannot have denominator 0");
  constexpr std::int64_t lowest = std::numeric_limits<std::int64_t>::min();
  if (numerator == lowest || denominator == lowest)  // its negation and its absolute value overflow
    throw InvalidArgument("a fraction's numerator and denominator must lie within +-(2^63 - 1)");
  if (denominator < 0) {
    numerator = -numerator;
    denominator = -denominator;
  }
  const std::int64_t g = std::gcd(numerator, denominator);
  numerator_ = numerator / g;
  denominator_ = denominator / g;
}

namespace {
std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool parse_integer(std::string_view s, std::int64_t& out) {
  s = trim(s);
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size();
}
}  // namespace

Fraction Fraction::parse(std::string_view text) {
  const auto bad = [&] {
    // Appended, not built with operator+ on a temporary: GCC 12 -O3 warns falsely (-Wrestrict) about the latter.
    std::string message = "'";
    message.append(text);
    message.append(
        "' is not an exact fraction; write it as \"a/b\" or \"a\" with integers a and b, for example "
        "\"4/3\" or \"2\"");
    return InvalidArgument(message);
  };
  std::int64_t numerator = 0;
  std::int64_t denominator = 1;
  const auto slash = text.find('/');
  if (slash == std::string_view::npos) {
    if (!parse_integer(text, numerator)) throw bad();
  } else if (!parse_integer(text.substr(0, slash), numerator) || !parse_integer(text.substr(slash + 1), denominator) ||
             denominator == 0) {
    throw bad();
  }
  return Fraction(numerator, denominator);
}

std::string Fraction::to_string() const {
  if (denominator_ == 1) return std::to_string(numerator_);
  return std::to_string(numerator_) + "/" + std::to_string(denominator_);
}

}  // namespace nonsep
