#include "nonsep/host/output_files.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "nonsep/host/number_format.hpp"

namespace nonsep::host {

namespace {
constexpr std::size_t buffer_capacity = 1 << 16;

std::string system_reason() { return std::strerror(errno); }
}  // namespace

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path, std::size_t dimension)
    : path_(path), dimension_(dimension) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw OutputError("cannot create " + path.string() + ": " + system_reason());
  buffer_.reserve(buffer_capacity + 1024);
  buffer_ += "trajectory,step,t";
  for (const char* name : {"q", "p"})
    for (std::size_t i = 0; i < dimension; ++i) {
      buffer_ += ',';
      buffer_ += name;
      buffer_ += std::to_string(i);
    }
  buffer_ += ",H,relative_energy_error\n";
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path, std::size_t dimension, std::uint64_t size)
    : path_(path), dimension_(dimension), flushed_size_(size) {
  std::error_code error;
  const auto existing = std::filesystem::file_size(path, error);
  if (error) throw OutputError("cannot resume " + path.string() + ": " + error.message());
  if (existing < size)
    throw OutputError("cannot resume " + path.string() + ": it has " + std::to_string(existing) +
                      " bytes, fewer than the " + std::to_string(size) + " the checkpoint recorded");
  std::filesystem::resize_file(path, size, error);
  if (error) throw OutputError("cannot resume " + path.string() + ": " + error.message());
  file_ = std::fopen(path.c_str(), "ab");
  if (!file_) throw OutputError("cannot open " + path.string() + ": " + system_reason());
  buffer_.reserve(buffer_capacity + 1024);
}

TrajectoryWriter::~TrajectoryWriter() {
  try {
    drain();
  } catch (const OutputError&) {
  }
  std::fclose(file_);
}

void TrajectoryWriter::write(std::size_t trajectory, std::uint64_t step, double t, std::span<const double> q,
                             std::span<const double> p, std::optional<double> energy,
                             std::optional<double> relative_energy_error) {
  buffer_ += std::to_string(trajectory);
  buffer_ += ',';
  buffer_ += std::to_string(step);
  buffer_ += ',';
  append_number(buffer_, t);
  for (std::size_t i = 0; i < dimension_; ++i) {
    buffer_ += ',';
    append_number(buffer_, q[i]);
  }
  for (std::size_t i = 0; i < dimension_; ++i) {
    buffer_ += ',';
    append_number(buffer_, p[i]);
  }
  buffer_ += ',';
  if (energy) append_number(buffer_, *energy);
  buffer_ += ',';
  if (relative_energy_error) append_number(buffer_, *relative_energy_error);
  buffer_ += '\n';
  if (buffer_.size() >= buffer_capacity) drain();
}

void TrajectoryWriter::drain() {
  if (buffer_.empty()) return;
  const std::size_t written = std::fwrite(buffer_.data(), 1, buffer_.size(), file_);
  if (written != buffer_.size()) {
    buffer_.clear();
    throw OutputError("cannot write " + path_.string() + ": " + system_reason());
  }
  flushed_size_ += buffer_.size();
  buffer_.clear();
}

void TrajectoryWriter::flush() {
  drain();
  if (std::fflush(file_) != 0) throw OutputError("cannot write " + path_.string() + ": " + system_reason());
}

namespace {
std::filesystem::path temporary_path_for(const std::filesystem::path& path) {
  std::string temporary_name = ".";
  temporary_name += path.filename().string();
  temporary_name += ".tmp-";
  temporary_name += std::to_string(::getpid());
  return path.parent_path() / temporary_name;
}
}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& path) : path_(path), temporary_(temporary_path_for(path)) {
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (!file_) throw OutputError("cannot create " + temporary_.string() + ": " + system_reason());
}

AtomicFile::~AtomicFile() {
  if (!file_) return;
  std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

void AtomicFile::write(std::string_view text) {
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size())
    throw OutputError("cannot write " + temporary_.string() + ": " + system_reason());
}

void AtomicFile::commit() {
  const bool written = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const std::string reason = system_reason();
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  std::error_code error;
  if (!written || !closed) {
    std::filesystem::remove(temporary_, error);
    throw OutputError("cannot write " + temporary_.string() + ": " + reason);
  }
  std::filesystem::rename(temporary_, path_, error);
  if (error) {
    const std::string rename_reason = error.message();
    std::filesystem::remove(temporary_, error);
    throw OutputError("cannot rename " + temporary_.string() + " to " + path_.string() + ": " + rename_reason);
  }
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  AtomicFile file(path);
  file.write(content);
  file.commit();
}

}  // namespace nonsep::host
