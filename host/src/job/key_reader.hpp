#pragma once
// Internal to the job reader (host/src/job/): one object of a job file read by its key table (job_keys.hpp). The
// table checks what it can say key by key: that the value is an object, that its keys are known ("did you mean"),
// that required keys are there, and each given value's type, range and choices (the items of a list of numbers
// too), in table order, with the rule's `allowed` text as the message; then the table's pairs of keys (exactly one
// of two, not both, both or neither). The section reader takes the checked values and keeps only the checks that
// relate a value to something outside its object (the state's dimension, t_end, the scheme's own verdict).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "job_keys.hpp"
#include "nonsep/core/base/fraction.hpp"
#include "nonsep/host/json/checker.hpp"

namespace nonsep::host::job_reader {

class KeyReader {
 public:
  // Reads `object` at `path` by `table`; `what` is the message for a value that is not an object.
  KeyReader(Checker& check, const json& object, std::string path, const KeyTable& table, const std::string& what);

  // Whether the value was an object (nothing else is read otherwise).
  bool is_object() const { return object_ != nullptr; }
  // The object read (only when is_object()).
  const json& object() const { return *object_; }
  // Key `key`'s value: present and valid by its rule; nullptr when absent or refused (an issue says which).
  const json* value(std::string_view key) const;
  // Whether `key` is present, valid or not.
  bool given(std::string_view key) const;
  // The checked value of a rule of that type (nothing when absent or refused).
  std::optional<double> number(std::string_view key) const;  // finite, nonzero, positive, nonnegative
  std::optional<std::int64_t> integer(std::string_view key) const;
  std::optional<bool> boolean(std::string_view key) const;
  std::optional<std::string> string(std::string_view key) const;  // string, path, text, choice, form
  // The checked items of a list of numbers (number_list): every item, or nothing when absent or refused.
  std::optional<std::vector<double>> numbers(std::string_view key) const;
  std::optional<std::vector<std::int64_t>> integers(std::string_view key) const;  // integer items
  // The items of a list of numbers that its item rule accepts, with their index, whether or not the list as a whole
  // was (for the checks a reader adds on each item: every problem at once); none when absent or not a list.
  std::vector<std::pair<std::size_t, const json*>> accepted_items(std::string_view key) const;
  // Whether the table's pairs of keys held (each broken pair is an issue).
  bool pairs_hold() const { return pairs_hold_; }
  // The JSON Pointer of `key`.
  std::string path(std::string_view key) const { return child(path_, std::string(key)); }

 private:
  bool valid(const json& value, const KeyRule& rule);
  bool valid_list(const json& value, const KeyRule& rule, const NumberList& list);
  void check_pair(const KeyPair& pair);

  Checker& check_;
  const json* object_ = nullptr;
  std::string path_;
  const KeyTable& table_;
  std::vector<std::string> refused_;  // present keys whose value its rule refused
  bool pairs_hold_ = true;
};

// A scheme's order as a job writes it (ValueType::order): an exact fraction as a string or an integral number.
std::optional<Fraction> order_value(const json& value);

// What a rule allows, for messages: its `allowed` text, or one built from its type and range.
std::string allowed_text(const KeyRule& rule);

}  // namespace nonsep::host::job_reader
