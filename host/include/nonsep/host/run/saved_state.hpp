#pragma once
// Saved state read back: the one reader of what a run saves for a resume (checkpoint.json, and in it each
// observer's state, CheckpointedObserver in observer.hpp). Numbers are stored as shortest round-trip strings
// (number_format.hpp: "0.1", "nan", "-inf"), so reading one back gives the same bits. Every check that fails throws
// CheckpointError "<whose> is damaged (<what>)<advice>": a damaged or edited state is refused with the same kind of
// message wherever it is.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace nonsep::host {

// A checkpoint cannot be read, belongs to another job, or does not fit it. The message names the file and says
// what to do.
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SavedState {
 public:
  // `whose`: how messages name the state ("its energy_error state", a file's path); `advice`: appended to them.
  explicit SavedState(std::string whose, std::string advice = "");
  // An observer's state: "its NAME state", which must be an object.
  static SavedState of_observer(const std::string& name, const nlohmann::json& state);

  [[noreturn]] void damaged(const std::string& what) const;

  // object[key]; damaged when object is not an object or has no `key`.
  const nlohmann::json& member(const nlohmann::json& object, const std::string& key) const;
  // A number as a string; damaged otherwise, `what` naming it.
  double number(const nlohmann::json& value, const std::string& what) const;
  // null: nothing; else number().
  std::optional<double> optional_number(const nlohmann::json& value, const std::string& what) const;
  // An array of `size` numbers.
  std::vector<double> numbers(const nlohmann::json& value, std::size_t size, const std::string& what) const;
  // An array of `size` entries (of any kind), for the caller to read one by one.
  const nlohmann::json& list(const nlohmann::json& value, std::size_t size, const std::string& what) const;
  // An integer >= 0 (and <= most).
  std::uint64_t count(const nlohmann::json& value, const std::string& what,
                      std::uint64_t most = static_cast<std::uint64_t>(-1)) const;
  std::string string(const nlohmann::json& value, const std::string& what) const;

 private:
  std::string whose_, advice_;
};

}  // namespace nonsep::host
