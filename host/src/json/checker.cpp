#include "nonsep/host/json/checker.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string_view>
#include <vector>

namespace nonsep::host {

namespace {
// Edits (insertions, deletions, substitutions) that turn a into b.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({above + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::string lower(std::string_view text) {
  std::string result(text);
  for (char& c : result) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return result;
}
}  // namespace

std::string to_string(const JobIssue& issue) {
  return (issue.path.empty() ? std::string("(document)") : issue.path) + ": found " + issue.found +
         "; allowed: " + issue.allowed;
}

bool looks_like_misspelling(std::string_view written, std::string_view meant) {
  if (written == meant) return false;
  if (lower(written) == lower(meant)) return true;
  const std::size_t shorter = std::min(written.size(), meant.size());
  if (shorter < 3) return false;
  return edit_distance(lower(written), lower(meant)) <= (shorter >= 6 ? 2u : 1u);
}

}  // namespace nonsep::host

namespace nonsep::host::job_reader {

std::string child(const std::string& path, const std::string& key) {
  return path + (json::json_pointer() / key).to_string();
}
std::string child(const std::string& path, std::size_t index) {
  return path + (json::json_pointer() / index).to_string();
}

std::string describe(const json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

std::optional<std::int64_t> integral_value(const json& value) {
  if (value.is_number_unsigned()) {
    const auto x = value.get<std::uint64_t>();
    if (x <= static_cast<std::uint64_t>(INT64_MAX)) return static_cast<std::int64_t>(x);
  } else if (value.is_number_integer()) {
    return value.get<std::int64_t>();
  } else if (value.is_number_float()) {
    // The bounds are checked on the double first: converting one outside the range of std::int64_t is undefined.
    const double x = value.get<double>();
    if (std::floor(x) == x && x >= -0x1p63 && x < 0x1p63) return static_cast<std::int64_t>(x);
  }
  return std::nullopt;
}

void Checker::issue(std::string path, std::string found, std::string allowed) {
  issues_.push_back({std::move(path), std::move(found), std::move(allowed)});
}

bool Checker::object(const json& value, const std::string& path, const std::string& what) {
  if (value.is_object()) return true;
  issue(path, describe(value), what);
  return false;
}

void Checker::known_keys(const json& object, const std::string& path, const std::vector<std::string>& allowed) {
  for (const auto& [key, value] : object.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string list;
    for (const auto& name : allowed) list += (list.empty() ? "" : ", ") + name;
    std::string found = "the unknown key \"" + key + "\"";
    for (const auto& name : allowed)
      if (!object.contains(name) && looks_like_misspelling(key, name)) {
        found += " (did you mean \"" + name + "\"?)";
        break;
      }
    issue(child(path, key), found, "only the keys " + list);
  }
}

const json* Checker::member(const json& object, const std::string& path, const std::string& key, bool required,
                            const std::string& what) {
  const auto it = object.find(key);
  if (it != object.end()) return &*it;
  if (!required) return nullptr;
  std::string found = "nothing (the key is missing";
  for (const auto& [name, value] : object.items())
    if (looks_like_misspelling(name, key)) {
      found += "; \"" + name + "\" is there: a misspelling of it?";
      break;
    }
  issue(child(path, key), found + ")", what);
  return nullptr;
}

std::optional<double> Checker::finite_number(const json& value, const std::string& path, const std::string& what) {
  if (value.is_number()) {
    const double x = value.get<double>();
    if (std::isfinite(x)) return x;
  }
  issue(path, describe(value), what);
  return std::nullopt;
}

std::optional<std::int64_t> Checker::integer(const json& value, const std::string& path, std::int64_t minimum,
                                             std::int64_t maximum, const std::string& what) {
  if (const auto x = integral_value(value); x && *x >= minimum && *x <= maximum) return x;
  issue(path, describe(value), what);
  return std::nullopt;
}

}  // namespace nonsep::host::job_reader
