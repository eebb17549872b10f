// Pass 1 of the job reader: strict JSON. nlohmann's SAX parser (iterative: one bit of state per open level) drives
// a builder that makes the document as nlohmann's own DOM parser would, but refuses duplicate keys and nesting
// deeper than max_nesting_depth. The depth limit keeps every later step bounded: the builder holds a JSON Pointer
// per open level (memory grows with the square of the depth), and serialising a value for a message recurses once
// per level (a 200 KB file nested 10^5 levels deep took 10 GB and then overflowed the stack).
#include "nonsep/host/json/strict_json.hpp"

#include <utility>

#include "nonsep/host/json/checker.hpp"
#include "nonsep/host/platform/installation.hpp"

namespace nonsep::host {

namespace {

using job_reader::child;
using nlohmann::json;

class StrictDocumentBuilder : public nlohmann::json_sax<json> {
 public:
  explicit StrictDocumentBuilder(std::vector<JobIssue>& issues) : issues_(issues) {}
  json& result() { return root_; }

  bool null() override { return add(nullptr); }
  bool boolean(bool value) override { return add(value); }
  bool number_integer(number_integer_t value) override { return add(value); }
  bool number_unsigned(number_unsigned_t value) override { return add(value); }
  bool number_float(number_float_t value, const string_t&) override { return add(value); }
  bool string(string_t& value) override { return add(value); }
  bool binary(binary_t& value) override { return add(json::binary(value)); }
  bool start_object(std::size_t) override { return open(json::object(), "an object"); }
  bool start_array(std::size_t) override { return open(json::array(), "an array"); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& key) override {
    Frame& frame = frames_.back();
    if (frame.value->contains(key))
      issues_.push_back({child(frame.path, key), "the key \"" + key + "\" a second time in the same object",
                         "each key at most once (JSON readers disagree on which duplicate wins)"});
    frame.key = key;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception& error) override {
    std::string message = error.what();
    const auto bracket = message.find("] ");
    if (message.rfind("[json.exception", 0) == 0 && bracket != std::string::npos) message = message.substr(bracket + 2);
    issues_.push_back({"", "text that is not JSON (" + message + ")",
                       "a JSON object as described in " + manual_location() + " and its docs/user-guide.md"});
    return false;
  }

 private:
  struct Frame {
    json* value;
    std::string path;
    std::string key;  // objects: the key whose value comes next
  };

  // The JSON Pointer of the value the parser is at.
  std::string next_path() const {
    if (frames_.empty()) return "";
    const Frame& frame = frames_.back();
    return frame.value->is_array() ? child(frame.path, frame.value->size()) : child(frame.path, frame.key);
  }
  // Places `value` where the parser is and returns it.
  json* place(json value) {
    if (frames_.empty()) {
      root_ = std::move(value);
      return &root_;
    }
    Frame& frame = frames_.back();
    if (frame.value->is_array()) {
      frame.value->push_back(std::move(value));
      return &frame.value->back();
    }
    json& slot = (*frame.value)[frame.key];
    slot = std::move(value);
    return &slot;
  }
  bool add(json value) {
    place(std::move(value));
    return true;
  }
  // Stops the parse (returning false) at the first container deeper than max_nesting_depth.
  bool open(json container, const char* what) {
    std::string path = next_path();
    if (frames_.size() >= max_nesting_depth) {
      issues_.push_back({std::move(path),
                         std::string(what) + " nested " + std::to_string(frames_.size() + 1) + " levels deep",
                         "at most " + std::to_string(max_nesting_depth) +
                             " levels of nesting (objects and arrays within each other; the document is level 1)"});
      return false;
    }
    json* where = place(std::move(container));
    frames_.push_back({where, std::move(path), {}});
    return true;
  }
  bool close() {
    frames_.pop_back();
    return true;
  }

  std::vector<JobIssue>& issues_;
  json root_;
  std::vector<Frame> frames_;
};

}  // namespace

std::optional<nlohmann::json> parse_job_text(const std::string& text, std::vector<JobIssue>& issues) {
  const std::size_t before = issues.size();
  // nlohmann's lexer takes a NUL byte for the end of the input: whatever follows one would be ignored unread.
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
    issues.push_back({"", "a NUL byte at byte offset " + std::to_string(nul) + " (counted from 0)",
                      "JSON text, which holds no NUL byte (a file cut or joined with binary data?)"});
    return std::nullopt;
  }
  StrictDocumentBuilder builder(issues);
  const bool parsed = json::sax_parse(text, &builder);
  if (!parsed || issues.size() != before) return std::nullopt;
  return std::move(builder.result());
}

}  // namespace nonsep::host
