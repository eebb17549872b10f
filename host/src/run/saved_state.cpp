#include "nonsep/host/run/saved_state.hpp"

#include <charconv>

namespace nonsep::host {

SavedState::SavedState(std::string whose, std::string advice) : whose_(std::move(whose)), advice_(std::move(advice)) {}

SavedState SavedState::of_observer(const std::string& name, const nlohmann::json& state) {
  SavedState read("its " + name + " state");
  if (!state.is_object()) read.damaged("not an object");
  return read;
}

void SavedState::damaged(const std::string& what) const {
  throw CheckpointError(whose_ + " is damaged (" + what + ")" + advice_);
}

const nlohmann::json& SavedState::member(const nlohmann::json& object, const std::string& key) const {
  if (!object.is_object() || !object.contains(key)) damaged("\"" + key + "\" is missing");
  return object.at(key);
}

double SavedState::number(const nlohmann::json& value, const std::string& what) const {
  if (!value.is_string()) damaged(what + " is not a number");
  const std::string& text = value.get_ref<const std::string&>();
  double x = 0.0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), x);
  if (result.ec != std::errc() || result.ptr != text.data() + text.size())
    damaged(what + " is not a number: \"" + text + "\"");
  return x;
}

std::optional<double> SavedState::optional_number(const nlohmann::json& value, const std::string& what) const {
  if (value.is_null()) return std::nullopt;
  return number(value, what);
}

std::vector<double> SavedState::numbers(const nlohmann::json& value, std::size_t size, const std::string& what) const {
  std::vector<double> result;
  result.reserve(size);
  for (const auto& x : list(value, size, what)) result.push_back(number(x, what));
  return result;
}

const nlohmann::json& SavedState::list(const nlohmann::json& value, std::size_t size, const std::string& what) const {
  if (!value.is_array() || value.size() != size) damaged(what + " does not have " + std::to_string(size) + " entries");
  return value;
}

std::uint64_t SavedState::count(const nlohmann::json& value, const std::string& what, std::uint64_t most) const {
  if (!value.is_number_unsigned() || value.get<std::uint64_t>() > most)
    damaged(what + (most == static_cast<std::uint64_t>(-1) ? " is not an integer >= 0"
                                                           : " is not an integer from 0 to " + std::to_string(most)));
  return value.get<std::uint64_t>();
}

std::string SavedState::string(const nlohmann::json& value, const std::string& what) const {
  if (!value.is_string()) damaged(what + " is not a string");
  return value.get<std::string>();
}

}  // namespace nonsep::host
