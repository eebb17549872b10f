#pragma once
// The one CSV writer of nonsep's outputs (trajectory.csv, trajectories.csv, convergence.csv, ...).
//
// Format: a header line, then one line per row; cells separated by ','; numbers shortest round-trip decimal
// (number_format.hpp: reading them back gives the same doubles), an unknown value an empty cell; text cells quoted
// only when they hold ',', '"' or a line break (RFC 4180). Lines end in '\n'.
//
// CsvAppender streams rows to a file as a run goes: rows are buffered (64 KiB) and handed to the file only as whole
// rows, one write() per buffer; a reader that finds a last line without its '\n' (after a hard kill or a full disk)
// must drop it. A whole file that is produced at once goes through write_file_atomically (atomic_files.hpp) instead.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "nonsep/host/number_format.hpp"

namespace nonsep::host {

// Appends `text` as one cell, quoted when it must be.
void append_csv_text(std::string& row, std::string_view text);
// Appends `value`, or nothing (an empty cell) when it is unknown.
inline void append_csv_number(std::string& row, std::optional<double> value) {
  if (value) append_number(row, *value);
}

class CsvAppender {
 public:
  // Creates or truncates `path` and writes `header` (without its '\n'). Throws OutputError.
  CsvAppender(const std::filesystem::path& path, std::string_view header);
  // Continues the file at `path` from its first `size` bytes (what a checkpoint recorded): the rest is cut off.
  // Throws OutputError, changing nothing, when the file is missing, shorter than `size`, or its first `size` bytes
  // do not have the content hash `prefix_hash` (content_hash.hpp) that flushed_hash() gave when they were written.
  CsvAppender(const std::filesystem::path& path, std::uint64_t size, std::uint64_t prefix_hash);
  CsvAppender(const CsvAppender&) = delete;
  CsvAppender& operator=(const CsvAppender&) = delete;
  // Hands what is buffered to the file; a failure here is lost, so callers flush() at the end of a run.
  ~CsvAppender();

  // The row to append to (cells, then end_row()).
  std::string& row() { return buffer_; }
  // Ends the current row with '\n'; writes the buffer out when it is full. Throws OutputError.
  void end_row();
  // Writes the buffer out. Throws OutputError.
  void flush();
  const std::filesystem::path& path() const { return path_; }
  // Bytes in the file after flush(), header included.
  std::uint64_t flushed_size() const { return flushed_size_; }
  // The content hash of those bytes.
  std::uint64_t flushed_hash() const { return flushed_hash_; }

 private:
  void open(int flags);

  std::filesystem::path path_;
  int descriptor_ = -1;
  std::uint64_t flushed_size_ = 0;
  std::uint64_t flushed_hash_;
  std::string buffer_;
};

// A streamed file's part of an observer's checkpoint state: after flushing `file`, {"bytes": its size, "content_hash":
// 16 hexadecimal digits of those bytes} (content_hash.hpp).
nlohmann::json csv_checkpoint_state(CsvAppender& file);
// Reopens the file at `path` from such a state (CsvAppender's resuming constructor). A state without a valid
// "bytes" and "content_hash" is reported through `damaged(what)`, which must throw.
template <class Damaged>
void resume_csv(std::optional<CsvAppender>& file, const std::filesystem::path& path, const nlohmann::json& state,
                Damaged&& damaged);

namespace detail {
// The byte count and content hash of a state, or the reason it has none.
struct CsvResumePoint {
  std::uint64_t bytes = 0, content_hash = 0;
  std::string problem;  // empty when the state is valid
};
CsvResumePoint csv_resume_point(const nlohmann::json& state, const std::filesystem::path& path);
}  // namespace detail

template <class Damaged>
void resume_csv(std::optional<CsvAppender>& file, const std::filesystem::path& path, const nlohmann::json& state,
                Damaged&& damaged) {
  const detail::CsvResumePoint point = detail::csv_resume_point(state, path);
  if (!point.problem.empty()) damaged(point.problem);
  file.reset();
  file.emplace(path, point.bytes, point.content_hash);
}

}  // namespace nonsep::host
