#pragma once
// The one CSV reader of the host: rows of a file as csv.hpp writes them (RFC 4180 quoting, '\n' line ends), read
// through a buffer of 1 MiB. results.h5's tables (hdf5_tables.hpp) and the merge of a distributed run's units
// (cluster/merge_outputs.hpp) read through it, and the initial states of a job (/initial/file), a file written by
// hand, with CsvReader::Rules.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace nonsep::host {

// What a file may hold besides what csv.hpp writes, and the bounds of a row, checked as it is read: a row's
// memory is at most about its cells times (8 times the largest cell plus 96 bytes), whatever the file.
struct CsvRules {
  // A file written by hand: its last line is a row without '\n' too, and "\r\n" ends a line as '\n' does. Otherwise
  // a last line without '\n' is a row cut short (by a stopped writer), not read.
  bool hand_written = false;
  std::size_t max_cells = std::numeric_limits<std::size_t>::max();       // per row
  std::size_t max_cell_bytes = std::numeric_limits<std::size_t>::max();  // unquoted, per cell
  std::string name;  // what messages call the file (its path when empty)
};

class CsvReader {
 public:
  using Rules = CsvRules;

  // Opens `path` (held_path, held_folder.hpp: also while its run folder is held). `purpose` ends the messages of the
  // OutputErrors it throws ("cannot read PATH PURPOSE"), when the file cannot be opened, or read.
  CsvReader(const std::filesystem::path& path, std::string purpose, Rules rules = {});

  // The next whole row into `cells` (whose strings are reused), or false at the end. Throws OutputError
  // "PATH:LINE: a quoted cell is not closed", "PATH:LINE: a row of more than N cells", "PATH:LINE: cell C, longer
  // than N bytes" (LINE where the reader is, before the rest of the row is read), or when the file cannot be read.
  bool next(std::vector<std::string>& cells);
  // The row last read as it is in the file, without its line end.
  const std::string& text() const { return text_; }
  // Where cell `cell` of that row starts in text().
  std::size_t offset(std::size_t cell) const { return offsets_[cell]; }
  // The rules, which may change between rows (a header read, the rows' bounds known).
  Rules& rules() { return rules_; }
  // The line of the file where that row ends.
  std::uint64_t line() const { return line_ - 1; }

 private:
  int peek();
  int get();
  void refill();
  [[noreturn]] void refuse(std::uint64_t line, const std::string& what) const;

  std::filesystem::path path_;
  std::string purpose_;
  Rules rules_;
  std::ifstream in_;
  std::vector<char> buffer_;
  std::size_t next_ = 0, end_ = 0;
  std::uint64_t line_ = 1;
  std::string text_;
  std::vector<std::size_t> offsets_;
};

}  // namespace nonsep::host
