#pragma once
// The files a run leaves behind: trajectory.csv, written as the run goes, and summary.json, written whole and
// atomically. Both live in the run's output folder.
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

// trajectory.csv: one row per sample, header
//   trajectory,step,t,q0,...,q<n-1>,p0,...,p<n-1>,H,relative_energy_error
// Numbers are shortest round-trip decimal (std::to_chars); H and relative_energy_error are empty when unknown.
// Rows are buffered (64 KiB) and go to the file when the buffer fills, on flush() and on destruction, so memory
// stays constant however long the run.
class TrajectoryWriter {
 public:
  // Creates or truncates `path` and writes the header. Throws OutputError.
  TrajectoryWriter(const std::filesystem::path& path, std::size_t dimension);
  // Resumes the file at `path`: cuts it back to its first `size` bytes (what a checkpoint recorded) and appends.
  // Throws OutputError when the file is missing or shorter than `size`.
  TrajectoryWriter(const std::filesystem::path& path, std::size_t dimension, std::uint64_t size);
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;
  // Flushes; a failure here is lost, so callers flush() explicitly at the end of a run.
  ~TrajectoryWriter();

  // q and p have `dimension` entries. Throws OutputError when the buffer cannot be written.
  void write(std::size_t trajectory, std::uint64_t step, double t, std::span<const double> q,
             std::span<const double> p, std::optional<double> energy, std::optional<double> relative_energy_error);
  // Writes the buffer to the file and flushes the stream. Throws OutputError.
  void flush();
  const std::filesystem::path& path() const { return path_; }
  // Bytes handed to the file so far, header included; after flush() they are all in it.
  std::uint64_t flushed_size() const { return flushed_size_; }

 private:
  void drain();

  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::size_t dimension_;
  std::uint64_t flushed_size_ = 0;
  std::string buffer_;
};

// A file written whole and then put in place atomically: the text goes to a temporary file in the same folder
// (".<name>.tmp-<pid>"), which commit() flushes to disk and renames over `path`; readers see the old file or the
// new one, never a part. Destroyed without commit(), the temporary file is removed and `path` left as it was.
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
