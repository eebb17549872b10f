#pragma once
// A number as summary.json writes it: the value, or null where there is none or it is not finite (JSON has no
// inf or nan).
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

namespace nonsep::host {

inline nlohmann::ordered_json finite_or_null(std::optional<double> value) {
  return value && std::isfinite(*value) ? nlohmann::ordered_json(*value) : nlohmann::ordered_json(nullptr);
}

}  // namespace nonsep::host
