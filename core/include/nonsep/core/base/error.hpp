#pragma once
// Errors raised by the core. The core never prints; it throws one of these with a message that names the
// offending value and says what is allowed. Callers (the host) translate them into exit statuses.
#include <stdexcept>
#include <string>

namespace nonsep {

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
