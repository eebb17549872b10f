#pragma once
// Strict JSON, pass 1 of the job reader and the whole syntax check of a formula model file (json/strict_json.cpp).
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "nonsep/host/json/issues.hpp"

namespace nonsep::host {

// Largest accepted nesting of objects and arrays (the document is level 1). A job needs 6; the limit bounds the
// reader's memory and the recursion of formatting a value for a message.
inline constexpr std::size_t max_nesting_depth = 64;

// Parses `text` as JSON, refusing duplicate keys (nlohmann would keep the last one silently) and nesting
// deeper than max_nesting_depth (naming the first value too deep). Returns nothing and adds issues on failure.
std::optional<nlohmann::json> parse_job_text(const std::string& text, std::vector<JobIssue>& issues);

}  // namespace nonsep::host
