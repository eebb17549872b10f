#pragma once
// The one CSV reader of the host: rows of a file as csv.hpp writes them (RFC 4180 quoting, '\n' line ends), read
// through a buffer of 1 MiB. results.h5's tables (hdf5_tables.hpp) and the merge of a distributed run's units
// (cluster/merge_outputs.hpp) read through it.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace nonsep::host {

class CsvReader {
 public:
  // Opens `path` (held_path, held_folder.hpp: also while its run folder is held). `purpose` ends the messages of the
  // OutputErrors it throws ("cannot read PATH PURPOSE"), when the file cannot be opened, or read.
  CsvReader(const std::filesystem::path& path, std::string purpose);

  // The next whole row into `cells` (whose strings are reused), or false at the end (a last line without '\n' is
  // not a row). Throws OutputError "PATH:LINE: a quoted cell is not closed", or when the file cannot be read.
  bool next(std::vector<std::string>& cells);
  // The row last read as it is in the file, without its '\n'.
  const std::string& text() const { return text_; }
  // Where cell `cell` of that row starts in text().
  std::size_t offset(std::size_t cell) const { return offsets_[cell]; }
  // The line of the file where that row ends.
  std::uint64_t line() const { return line_ - 1; }

 private:
  int peek();
  int get();
  void refill();

  std::filesystem::path path_;
  std::string purpose_;
  std::ifstream in_;
  std::vector<char> buffer_;
  std::size_t next_ = 0, end_ = 0;
  std::uint64_t line_ = 1;
  std::string text_;
  std::vector<std::size_t> offsets_;
};

}  // namespace nonsep::host
