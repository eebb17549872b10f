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
// removed and `path` left as it was. In a held folder (held_folder.hpp) both go through the folder's descriptor.
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
  void discard();  // removes the temporary file and lets go of the folder

  std::filesystem::path path_, temporary_;  // as given, for messages
  int folder_ = -1;                         // the folder's descriptor (AT_FDCWD outside held folders)
  std::string temporary_name_;              // the temporary file's name relative to folder_
  std::FILE* file_ = nullptr;
};

// Removes the file at `path` if it is there (in a held folder through its descriptor). Never throws.
void remove_file(const std::filesystem::path& path);

// What a file that is not a regular one is, for messages: "a folder", "a symbolic link", "a FIFO (named pipe)",
// "a device", "a socket". `mode` is a stat's st_mode.
std::string file_kind(unsigned mode);

// Opens the regular file at `path` for reading, without following a symbolic link at its last component and without
// blocking (a FIFO there would wait for a writer forever); its type is checked through the descriptor. -1 when
// nothing is there. Throws OutputError naming the file and what it is when it is not a regular file, or when it
// cannot be opened.
int open_regular_file(const std::filesystem::path& path);

// Opens the regular file at `path` for writing with `flags` (O_WRONLY or O_RDWR, with O_CREAT | O_TRUNC to create
// it, O_APPEND, ...), without following a symbolic link at its last component and without blocking (a FIFO there
// would wait for a reader forever); its type is checked through the descriptor, which is then blocking. Throws
// OutputError "<verb><path>: <reason>" (verb such as "cannot create ").
int open_regular_file_for_writing(const std::filesystem::path& path, int flags, const std::string& verb);

// The content of the regular file at `path` (open_regular_file), at most its first `limit` bytes; nothing when
// nothing is there. Throws OutputError as open_regular_file does, or when it cannot be read.
std::optional<std::string> read_regular_file(const std::filesystem::path& path,
                                             std::size_t limit = static_cast<std::size_t>(-1));

// Replaces the file at `path` with `content` atomically (AtomicFile). Throws OutputError (the temporary file is
// removed).
void write_file_atomically(const std::filesystem::path& path, const std::string& content);

}  // namespace nonsep::host
