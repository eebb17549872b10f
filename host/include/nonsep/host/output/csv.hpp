#pragma once
// The one CSV writer of nonsep's outputs (trajectory.csv, trajectories.csv, convergence.csv, ...).
//
// Format: a header line, then one line per row; cells separated by ','; numbers shortest round-trip decimal
// (number_format.hpp: reading them back gives the same doubles), an unknown value an empty cell; text cells quoted
// only when they hold ',', '"' or a line break (RFC 4180). Lines end in '\n'.
//
// CsvAppender streams rows to a file as a run goes: rows are buffered (64 KiB) and handed to the file only as whole
// rows, one write() per buffer; a reader that finds a last line without its '\n' (after a hard kill or a full disk)
// must drop it. A whole file that is produced at once goes through write_file_atomically (files.hpp) instead.
#include <cstdint>
#include <filesystem>
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

}  // namespace nonsep::host
