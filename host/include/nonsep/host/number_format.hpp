#pragma once
// Shortest round-trip decimal text of a double (std::to_chars): reading the text back gives the same double bit
// for bit. Used for every number nonsep writes to CSV.
#include <charconv>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace nonsep::host {

// Appends the shortest text that round-trips to `value` ("0.1", "-1.5e-07", "inf", "nan").
inline void append_number(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

inline std::string format_number(double value) {
  std::string text;
  append_number(text, value);
  return text;
}

}  // namespace nonsep::host

namespace nonsep::host {

// n as an English ordinal: "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "102nd".
inline std::string ordinal(unsigned long long n) {
  const unsigned long long tens = n % 100, units = n % 10;
  const char* suffix = tens >= 11 && tens <= 13 ? "th"
                       : units == 1             ? "st"
                       : units == 2             ? "nd"
                       : units == 3             ? "rd"
                                                : "th";
  return std::to_string(n) + suffix;
}

// A count with its noun: "1 value", "2 values" (`plural` where it is not the noun and an s: "2 trajectories").
inline std::string counted(std::size_t count, const std::string& noun, const std::string& plural = "") {
  return std::to_string(count) + " " + (count == 1 ? noun : plural.empty() ? noun + "s" : plural);
}

// The double written by append_number (the whole of `text`, nothing else), or nothing.
inline std::optional<double> parse_number(std::string_view text) {
  double x = 0.0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), x);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size()) return std::nullopt;
  return x;
}

}  // namespace nonsep::host
