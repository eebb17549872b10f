#include "nonsep/host/summary_json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "nonsep/host/output_files.hpp"

namespace nonsep::host {

namespace {

using json = nlohmann::ordered_json;

std::string dump(const json& value, int indent = -1) {
  return value.dump(indent, ' ', false, json::error_handler_t::replace);
}

void append_integer(std::string& out, std::uint64_t value) {
  char buffer[24];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

void append_optional(std::string& out, std::optional<double> value) {
  if (value)
    append_json_number(out, *value);
  else
    out += "null";
}

// Plain printable ASCII goes straight in (statuses, variable names); anything else through nlohmann's escaping.
void append_string(std::string& out, const std::string& text) {
  const bool plain = std::all_of(text.begin(), text.end(),
                                 [](char c) { return c >= 0x20 && c < 0x7f && c != '"' && c != '\\'; });
  if (!plain) {
    out += dump(json(text));
    return;
  }
  out += '"';
  out += text;
  out += '"';
}

// The layout of nlohmann's dump(2): `indent` spaces before each key, members separated by ",\n".
class ObjectWriter {
 public:
  ObjectWriter(std::string& out, int indent) : out_(out), indent_(indent) { out_ += "{\n"; }
  // Starts the member `key`; the caller appends its value.
  std::string& key(const char* key) {
    if (!first_) out_ += ",\n";
    first_ = false;
    out_.append(static_cast<std::size_t>(indent_), ' ');
    out_ += '"';
    out_ += key;
    out_ += "\": ";
    return out_;
  }
  void number(const char* name, double value) { append_json_number(key(name), value); }
  void integer(const char* name, std::uint64_t value) { append_integer(key(name), value); }
  void numbers(const char* name, std::span<const double> values) {
    key(name);
    if (values.empty()) {
      out_ += "[]";
      return;
    }
    out_ += "[\n";
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i > 0) out_ += ",\n";
      out_.append(static_cast<std::size_t>(indent_ + 2), ' ');
      append_json_number(out_, values[i]);
    }
    out_ += '\n';
    out_.append(static_cast<std::size_t>(indent_), ' ');
    out_ += ']';
  }
  void close() {
    out_ += '\n';
    out_.append(static_cast<std::size_t>(indent_ - 2), ' ');
    out_ += '}';
  }

 private:
  std::string& out_;
  int indent_;
  bool first_ = true;
};

void append_entry(std::string& out, std::size_t index, const TrajectoryRecord& record, std::span<const double> q0,
                  std::span<const double> p0, bool closest_return) {
  constexpr int depth = 6;  // the entry's keys: inside the top-level object and the /trajectories array
  ObjectWriter entry(out, depth);
  entry.integer("index", index);
  append_string(entry.key("status"), record.status);
  {
    ObjectWriter initial(entry.key("initial"), depth + 2);
    initial.numbers("q", q0);
    initial.numbers("p", p0);
    initial.close();
  }
  {
    ObjectWriter final_state(entry.key("final"), depth + 2);
    final_state.number("t", record.final_t);
    final_state.integer("step", record.final_step);
    final_state.numbers("q", record.final_q);
    final_state.numbers("p", record.final_p);
    final_state.close();
  }
  {
    const bool relative_known = record.energy_initial && *record.energy_initial != 0.0;
    ObjectWriter energy(entry.key("energy"), depth + 2);
    append_optional(energy.key("initial"), record.energy_initial);
    append_optional(energy.key("final"), record.energy_final);
    append_optional(energy.key("relative_error_final"),
                    relative_energy_error(record.energy_final, record.energy_initial));
    append_optional(energy.key("relative_error_max_abs"),
                    relative_known ? std::optional<double>(record.max_abs_relative_error) : std::nullopt);
    energy.close();
  }
  if (record.status == "diverged") {
    ObjectWriter diverged(entry.key("diverged"), depth + 2);
    diverged.integer("step", record.diverged_step);
    diverged.number("t", record.diverged_t);
    append_string(diverged.key("variable"), record.diverged_variable);
    diverged.close();
  }
  if (!record.error.empty()) append_string(entry.key("error"), record.error);
  if (closest_return) {
    if (record.closest_distance) {
      ObjectWriter closest(entry.key("closest_return"), depth + 2);
      closest.number("distance", *record.closest_distance);
      closest.number("t", record.closest_t);
      closest.integer("step", record.closest_step);
      closest.close();
    } else {
      entry.key("closest_return") += "null";
    }
  }
  entry.close();
}

// Bytes of one entry, generously: its keys and layout, and 4 numbers per dimension.
std::size_t entry_size_estimate(std::size_t dimension) { return 480 + 160 * dimension; }

}  // namespace

void append_json_number(std::string& out, double value) {
  if (!std::isfinite(value)) {
    out += "null";
    return;
  }
  // The shortest round-trip digits d.ddd and exponent E (std::to_chars, scientific), laid out by nlohmann's
  // format_buffer (kMinExp -4, kMaxExp 15): with k digits and n = E + 1, plain decimal when -4 < n <= 15,
  // scientific otherwise. Composed in a local buffer and appended once.
  if (value == 0.0) {
    out += std::signbit(value) ? "-0.0" : "0.0";
    return;
  }
  char text[48];
  char* at = text;
  if (value < 0.0) {
    *at++ = '-';
    value = -value;
  }
  char scientific[32];
  const char* const end = std::to_chars(scientific, scientific + sizeof scientific, value,
                                        std::chars_format::scientific).ptr;
  char digits[20];
  int k = 0;
  const char* c = scientific;
  for (; *c != 'e'; ++c)
    if (*c != '.') digits[k++] = *c;
  int exponent = 0;
  std::from_chars(c + (c[1] == '+' ? 2 : 1), end, exponent);
  const int n = exponent + 1;
  const auto put = [&](const char* from, int count) {
    for (int i = 0; i < count; ++i) *at++ = from[i];
  };
  if (k <= n && n <= 15) {
    put(digits, k);
    for (int i = k; i < n; ++i) *at++ = '0';
    put(".0", 2);
  } else if (0 < n && n <= 15) {
    put(digits, n);
    *at++ = '.';
    put(digits + n, k - n);
  } else if (-4 < n && n <= 0) {
    put("0.", 2);
    for (int i = 0; i < -n; ++i) *at++ = '0';
    put(digits, k);
  } else {
    *at++ = digits[0];
    if (k > 1) {
      *at++ = '.';
      put(digits + 1, k - 1);
    }
    const int shown = n - 1;
    *at++ = 'e';
    *at++ = shown < 0 ? '-' : '+';
    const int magnitude = shown < 0 ? -shown : shown;
    if (magnitude < 10) *at++ = '0';
    at = std::to_chars(at, text + sizeof text, magnitude).ptr;
  }
  out.append(text, static_cast<std::size_t>(at - text));
}

namespace {

// Calls `sink` with consecutive pieces of /trajectories, "[" to "]". Entries are formatted in rounds: each of up
// to `threads` threads formats a run of consecutive entries into its own buffer, and the buffers go to the sink
// in order, so the text is the same for any number of threads and the memory is a few buffers, whatever the
// number of trajectories.
void emit_entries(const TrajectoryEntries& entries, unsigned threads,
                  const std::function<void(std::string_view)>& sink) {
  const std::size_t count = entries.records.size();
  if (count == 0) {
    sink("[]");
    return;
  }
  const std::size_t n = entries.dimension;
  constexpr std::size_t run = 256;  // entries per thread and round
  const std::size_t parts = std::clamp<std::size_t>((count + run - 1) / run, 1, std::max(threads, 1u));
  std::vector<std::string> texts(parts);
  std::vector<std::exception_ptr> errors(parts);  // an exception may not leave an OpenMP region
  for (std::string& text : texts) text.reserve(run * entry_size_estimate(n));
  sink("[\n");
  for (std::size_t round = 0; round < count; round += parts * run) {
#pragma omp parallel for num_threads(static_cast<int>(parts)) schedule(static, 1) if (parts > 1)
    for (std::size_t part = 0; part < parts; ++part) {
      try {
        std::string& text = texts[part];
        text.clear();
        const std::size_t begin = std::min(count, round + part * run), end = std::min(count, begin + run);
        for (std::size_t index = begin; index < end; ++index) {
          if (index > 0) text += ",\n";
          text += "    ";
          append_entry(text, index, entries.records[index], entries.initial_q.subspan(index * n, n),
                       entries.initial_p.subspan(index * n, n), entries.closest_return);
        }
      } catch (...) {
        errors[part] = std::current_exception();
      }
    }
    for (const auto& error : errors)
      if (error) std::rethrow_exception(error);
    for (const std::string& text : texts) sink(text);
  }
  sink("\n  ]");
}

void emit_summary(const json& header, const TrajectoryEntries& entries, unsigned threads,
                  const std::function<void(std::string_view)>& sink) {
  const std::string head = dump(header, 2);
  // A string value cannot hold a raw newline, so a line starting with two spaces and this key is the top-level
  // member and nothing else.
  constexpr std::string_view placeholder = "\n  \"trajectories\": null";
  const auto at = head.find(placeholder);
  if (at == std::string::npos) throw std::logic_error("summary.json: the header has no \"trajectories\": null");
  const std::string_view text(head);
  sink(text.substr(0, at + placeholder.size() - 4));
  emit_entries(entries, threads, sink);
  sink(text.substr(at + placeholder.size()));
  sink("\n");
}

}  // namespace

std::string summary_json_text(const json& header, const TrajectoryEntries& entries, unsigned threads) {
  std::string text;
  emit_summary(header, entries, threads, [&](std::string_view piece) { text += piece; });
  return text;
}

void write_summary_json(const std::filesystem::path& path, const json& header, const TrajectoryEntries& entries,
                        unsigned threads) {
  AtomicFile file(path);
  emit_summary(header, entries, threads, [&](std::string_view piece) { file.write(piece); });
  file.commit();
}

}  // namespace nonsep::host
