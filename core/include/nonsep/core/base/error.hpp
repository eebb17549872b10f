#pragma once
// Errors raised by the core. The core never prints; it throws one of these with a message that names the
// offending value and says what is allowed. Callers (the host) translate them into exit statuses.
#include <charconv>
#include <stdexcept>
#include <string>

namespace nonsep {

// A number as a message shows what was found: the shortest text that reads back as the same double ("2.5", "0",
// "1e-20", "inf"), where std::to_string would print "2.500000", "0.000000" and "0.000000". The messages give the
// offending value last, as " (found X)", so that a caller presenting the rule beside the value it found itself (the
// host's job reader) can leave that part out.
inline std::string found_number(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

// A parameter or argument outside its documented domain: t2 = 0, non-finite dt, an order that does not exist,
// a batch whose shape disagrees with the model.
class InvalidArgument : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// A model failed while being evaluated (for example a plugin returned an error status). Raised by model
// adapters, propagated unchanged through the integrators.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace nonsep
