#pragma once
// The typed reads of the JSON readers (the job reader, host/src/job/, and the formula model reader,
// host/src/formula/): JSON Pointers, the shortened description of a found value, and Checker, the typed reads every
// section uses. Each read of Checker either returns the value or adds one JobIssue
// (path, what was found, what is allowed) and returns nothing, so a section goes on and reports all its problems.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "nonsep/host/json/issues.hpp"

namespace nonsep::host::job_reader {

using nlohmann::json;

// RFC 6901: the pointer to member `key` ('~' and '/' escaped) or element `index` of the value at `path`.
std::string child(const std::string& path, const std::string& key);
std::string child(const std::string& path, std::size_t index);

// What was found, for messages: the JSON text, cut to 60 characters. `value` is at most max_nesting_depth deep
// (parse_job_text refuses deeper documents), which bounds the recursion of its serialisation.
std::string describe(const json& value);

// An integral JSON number in the range of std::int64_t: an integer, or a float with an integral value (JSON Schema
// counts 10.0 as an integer; so does nonsep). Nothing otherwise.
std::optional<std::int64_t> integral_value(const json& value);

class Checker {
 public:
  explicit Checker(std::vector<JobIssue>& issues) : issues_(issues) {}

  void issue(std::string path, std::string found, std::string allowed);
  std::size_t issue_count() const { return issues_.size(); }
  std::vector<JobIssue>& issues() { return issues_; }

  // True for an object; otherwise an issue saying `what` is allowed.
  bool object(const json& value, const std::string& path, const std::string& what);
  // Reports every key of `object` not in `allowed`.
  // Unknown keys are reported with the allowed key they most likely misspell, if any ("did you mean").
  void known_keys(const json& object, const std::string& path, const std::vector<std::string>& allowed);
  // The member `key` of an object, or nullptr; a missing `required` member is an issue.
  const json* member(const json& object, const std::string& path, const std::string& key, bool required,
                     const std::string& what);

  std::optional<double> finite_number(const json& value, const std::string& path, const std::string& what);
  // An integral_value within [minimum, maximum].
  std::optional<std::int64_t> integer(const json& value, const std::string& path, std::int64_t minimum,
                                      std::int64_t maximum, const std::string& what);

 private:
  std::vector<JobIssue>& issues_;
};

}  // namespace nonsep::host::job_reader
