// Reading one object of a job file by its key table (key_reader.hpp).
#include "key_reader.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "nonsep/core/base/error.hpp"
#include "nonsep/core/base/fraction.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::job_reader {

std::string allowed_text(const KeyRule& rule) {
  if (!rule.allowed.empty()) return rule.allowed;
  switch (rule.type) {
    case ValueType::finite:
      if (std::isfinite(rule.at_least) || std::isfinite(rule.at_most))
        return "a number from " + format_number(rule.at_least) + " to " + format_number(rule.at_most);
      return "a finite number";
    case ValueType::order:
      return "an exact fraction as a string (\"4/3\") or an integer (2)";
    case ValueType::nonzero:
      return "a finite non-zero number";
    case ValueType::positive:
      return "a finite number > 0";
    case ValueType::nonnegative:
      return "a finite number >= 0";
    case ValueType::integer:
      return "an integer from " + std::to_string(rule.minimum) + " to " + std::to_string(rule.maximum);
    case ValueType::boolean:
      return "true or false";
    case ValueType::text:
      return "a string";
    case ValueType::string:
      return "a non-empty string";
    case ValueType::path:
      return "a non-empty path";
    case ValueType::choice:
    case ValueType::form: {
      std::vector<std::string> names = rule.choices;
      if (rule.type == ValueType::form)
        for (const auto& form : hamiltonian_forms()) names.push_back(form.name);
      std::string list;
      for (std::size_t i = 0; i < names.size(); ++i)
        list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("\"" + names[i] + "\"");
      return list;
    }
    case ValueType::object:
    case ValueType::defined:
      return rule.description;
  }
  return rule.description;
}

KeyReader::KeyReader(Checker& check, const json& object, std::string path, const KeyTable& table,
                     const std::string& what)
    : check_(check), path_(std::move(path)), table_(table) {
  if (!check_.object(object, path_, what)) return;
  object_ = &object;
  check_.known_keys(object, path_, table.names());
  for (const KeyRule& rule : table.rules) {
    const auto it = object.find(rule.name);
    if (it == object.end()) {
      if (rule.required) check_.member(object, path_, rule.name, true, allowed_text(rule));
    } else if (!valid(*it, rule)) {
      refused_.push_back(rule.name);
    }
  }
  for (const KeyPair& pair : table.pairs) check_pair(pair);
}

void KeyReader::check_pair(const KeyPair& pair) {
  const bool first = object_->contains(pair.first), second = object_->contains(pair.second);
  if (first && second && pair.kind != KeyPair::Kind::together) {
    check_.issue(path(pair.second), describe((*object_)[pair.second]) + " together with " + path(pair.first),
                 pair.allowed);
    pairs_hold_ = false;
  } else if (!first && !second && pair.kind == KeyPair::Kind::exactly_one) {
    check_.issue(path(pair.first), "nothing (neither \"" + pair.first + "\" nor \"" + pair.second + "\" is given)",
                 pair.allowed);
    pairs_hold_ = false;
  } else if (first != second && pair.kind == KeyPair::Kind::together) {
    const std::string& given = first ? pair.first : pair.second;
    check_.issue(path(first ? pair.second : pair.first), "nothing, while \"" + given + "\" is given", pair.allowed);
    pairs_hold_ = false;
  }
}

namespace {

// Whether `value` is of the rule's type, in its range and among its choices. The messages are built only for a
// value refused (a job may hold a million states, each read by a table).
bool accepted(const json& value, const KeyRule& rule) {
  const auto number = [&](auto&& holds) {
    if (!value.is_number()) return false;
    const double x = value.get<double>();
    return std::isfinite(x) && holds(x);
  };
  switch (rule.type) {
    case ValueType::finite:
      return number([&](double x) { return x >= rule.at_least && x <= rule.at_most; });
    case ValueType::nonzero:
      return number([](double x) { return x != 0.0; });
    case ValueType::positive:
      return number([](double x) { return x > 0.0; });
    case ValueType::nonnegative:
      return number([](double x) { return x >= 0.0; });
    case ValueType::integer: {
      const auto x = integral_value(value);
      return x && *x >= rule.minimum && *x <= rule.maximum;
    }
    case ValueType::boolean:
      return value.is_boolean();
    case ValueType::text:
      return value.is_string();
    case ValueType::string:
    case ValueType::path:
      return value.is_string() && !value.get_ref<const std::string&>().empty();
    case ValueType::choice:
      return value.is_string() && std::ranges::find(rule.choices, value.get<std::string>()) != rule.choices.end();
    case ValueType::form:
      return value.is_string() && std::ranges::any_of(hamiltonian_forms(), [&](const FormName& form) {
               return form.name == value.get<std::string>();
             });
    case ValueType::order:
      return order_value(value).has_value();
    case ValueType::object:
    case ValueType::defined:
      return true;  // the section reader reads what is inside (a list of numbers: KeyReader::valid_list)
  }
  return true;
}

}  // namespace

std::optional<Fraction> order_value(const json& value) {
  try {
    if (value.is_string()) return Fraction::parse(value.get<std::string>());
    if (const auto integral = integral_value(value)) return Fraction(*integral);
  } catch (const InvalidArgument&) {
  }
  return std::nullopt;
}

bool KeyReader::valid_list(const json& value, const KeyRule& rule, const NumberList& list) {
  const std::string at = child(path_, rule.name);
  if (!value.is_array() || value.empty()) {
    check_.issue(at, describe(value), rule.allowed.empty() ? list.allowed : rule.allowed);
    return false;
  }
  if (value.size() > list.max_items) {  // refused from its size, before any item is read
    check_.issue(at, std::to_string(value.size()) + " numbers",
                 "at most " + std::to_string(list.max_items) + " numbers");
    return false;
  }
  bool ok = true;
  std::unordered_set<std::int64_t> seen;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const json& item = value[i];
    if (!accepted(item, list.item)) {
      check_.issue(child(at, i), describe(item), allowed_text(list.item));
      ok = false;
    } else if (list.distinct && !seen.insert(*integral_value(item)).second) {
      check_.issue(child(at, i), describe(item) + ", given before", rule.allowed.empty() ? list.allowed : rule.allowed);
      ok = false;
    }
  }
  return ok;
}

bool KeyReader::valid(const json& value, const KeyRule& rule) {
  if (rule.type == ValueType::defined)
    if (const NumberList* list = number_list(rule.definition)) return valid_list(value, rule, *list);
  if (!accepted(value, rule)) {
    std::string found = describe(value);
    if (rule.type == ValueType::choice && value.is_string())  // "gaus": did you mean "gauss"?
      if (const auto meant = std::ranges::find_if(
              rule.choices,
              [&](const std::string& name) { return looks_like_misspelling(value.get<std::string>(), name); });
          meant != rule.choices.end())
        found += " (did you mean \"" + *meant + "\"?)";
    check_.issue(child(path_, rule.name), found, allowed_text(rule));
    return false;
  }
  // A path the file system cannot take.
  if (rule.type == ValueType::path && value.get_ref<const std::string&>().find('\0') != std::string::npos) {
    check_.issue(child(path_, rule.name), describe(value) + ", which contains NUL (\\u0000)",
                 allowed_text(rule) + ", without NUL characters");
    return false;
  }
  return true;
}

const json* KeyReader::value(std::string_view key) const {
  const KeyRule& rule = table_[key];  // a key without a rule is a programming error
  if (!object_ || std::ranges::find(refused_, rule.name) != refused_.end()) return nullptr;
  const auto it = object_->find(rule.name);
  return it == object_->end() ? nullptr : &*it;
}

bool KeyReader::given(std::string_view key) const { return object_ && object_->contains(table_[key].name); }

std::optional<double> KeyReader::number(std::string_view key) const {
  const json* v = value(key);
  return v ? std::optional<double>(v->get<double>()) : std::nullopt;
}

std::optional<std::int64_t> KeyReader::integer(std::string_view key) const {
  const json* v = value(key);
  return v ? integral_value(*v) : std::nullopt;
}

std::optional<bool> KeyReader::boolean(std::string_view key) const {
  const json* v = value(key);
  return v ? std::optional<bool>(v->get<bool>()) : std::nullopt;
}

std::optional<std::string> KeyReader::string(std::string_view key) const {
  const json* v = value(key);
  return v ? std::optional<std::string>(v->get<std::string>()) : std::nullopt;
}

std::vector<std::pair<std::size_t, const json*>> KeyReader::accepted_items(std::string_view key) const {
  const KeyRule& rule = table_[key];
  const NumberList* list = number_list(rule.definition);
  std::vector<std::pair<std::size_t, const json*>> items;
  if (!object_ || !list || !object_->contains(rule.name)) return items;
  const json& value = (*object_)[rule.name];
  if (!value.is_array() || value.size() > list->max_items) return items;
  for (std::size_t i = 0; i < value.size(); ++i)
    if (accepted(value[i], list->item)) items.emplace_back(i, &value[i]);
  return items;
}

std::optional<std::vector<double>> KeyReader::numbers(std::string_view key) const {
  const json* v = value(key);
  if (!v) return std::nullopt;
  std::vector<double> items;
  items.reserve(v->size());
  for (const json& item : *v) items.push_back(item.get<double>());
  return items;
}

std::optional<std::vector<std::int64_t>> KeyReader::integers(std::string_view key) const {
  const json* v = value(key);
  if (!v) return std::nullopt;
  std::vector<std::int64_t> items;
  items.reserve(v->size());
  for (const json& item : *v) items.push_back(*integral_value(item));
  return items;
}

}  // namespace nonsep::host::job_reader
