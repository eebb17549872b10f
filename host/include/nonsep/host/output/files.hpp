#pragma once
// Files written whole and put in place atomically (summary.json, trajectories.csv, checkpoint.json), and the error
// every output failure is reported with. Streamed CSV files are csv.hpp.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace nonsep::host {

// A file could not be created, written or renamed. The message names the file and the system's reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A file written whole and then put in place atomically: the text goes to a temporary file in the same folder
// (".<name>.tmp-" and six random characters, created exclusively), which commit() flushes to disk and renames over
// `path`; readers see the old file or the new one, never a part. Destroyed without commit(), the temporary file is
// removed and `path` left as it was.
class AtomicFile {
 public:
  // Throws OutputError when the temporary file cannot be created.
  explicit AtomicFile(const std::filesystem::path& path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();
  // Appends to the temporary file (stdio-buffered). Throws OutputError.
  void write(std::string_view text);
  // Flushes, syncs and renames. Throws OutputError (the temporary file is removed).
  void commit();

 private:
  std::filesystem::path path_, temporary_;
  std::FILE* file_ = nullptr;
};

// Replaces the file at `path` with `content` atomically (AtomicFile). Throws OutputError (the temporary file is
// removed).
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace nonsep::host
