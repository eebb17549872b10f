#include "nonsep/host/output/files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include "nonsep/host/output/content_hash.hpp"

namespace nonsep::host {

std::optional<std::uint64_t> descriptor_content_hash(int descriptor, std::optional<std::uint64_t> size) {
  // The bound as a plain number (all of the file: the largest), so that nothing below depends on an empty
  // optional's unset value.
  const bool exact = size.has_value();
  const std::uint64_t end = exact ? *size : std::numeric_limits<std::uint64_t>::max();
  std::uint64_t hash = content_hash_start, offset = 0;
  std::string buffer(1 << 16, '\0');
  while (offset < end) {
    const auto want = static_cast<std::size_t>(std::min<std::uint64_t>(end - offset, buffer.size()));
    const ssize_t got = ::pread(descriptor, buffer.data(), want, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return std::nullopt;
    if (got == 0) break;
    hash = content_hash(std::string_view(buffer.data(), static_cast<std::size_t>(got)), hash);
    offset += static_cast<std::uint64_t>(got);
  }
  if (exact && offset < end) return std::nullopt;
  return hash;
}

std::optional<std::uint64_t> file_content_hash(const std::filesystem::path& path, std::optional<std::uint64_t> size) {
  const int descriptor = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (descriptor < 0) return std::nullopt;
  const auto hash = descriptor_content_hash(descriptor, size);
  ::close(descriptor);
  return hash;
}

namespace {
std::string system_reason() { return std::strerror(errno); }
}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& path) : path_(path) {
  // An unpredictable name, created exclusively (mkstemp: O_CREAT | O_EXCL, which also refuses a symbolic link
  // planted there), so that nothing else can be made to receive the text.
  std::string pattern = (path.parent_path() / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
  const int descriptor = ::mkstemp(pattern.data());
  if (descriptor < 0) {
    const int error = errno;
    const auto folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
    if (error == EACCES || error == EROFS || error == EPERM)
      throw OutputError("the folder " + folder.string() + " is not writable (" + std::strerror(error) + "), so " +
                        path.filename().string() + " cannot be written there");
    throw OutputError("cannot create a temporary file for " + path.string() + ": " + std::strerror(error));
  }
  temporary_ = pattern;
  ::fchmod(descriptor, 0644);
  file_ = ::fdopen(descriptor, "wb");
  if (!file_) {
    const std::string reason = system_reason();
    ::close(descriptor);
    std::filesystem::remove(temporary_);
    throw OutputError("cannot open " + temporary_.string() + ": " + reason);
  }
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
