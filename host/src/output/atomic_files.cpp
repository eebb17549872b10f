#include "nonsep/host/output/atomic_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>

#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/held_folder.hpp"

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

std::string file_kind(unsigned mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  return S_ISREG(mode) ? "a regular file" : "not a regular file";
}

int open_regular_file(const std::filesystem::path& path) {
  const FileLocation location(path);
  const int descriptor = ::openat(location.folder(), location.name(), O_RDONLY | O_NONBLOCK | O_NOFOLLOW | O_CLOEXEC);
  if (descriptor < 0) {
    const int error = errno;
    if (error == ENOENT) return -1;
    struct stat status {};
    if (error == ELOOP && ::fstatat(location.folder(), location.name(), &status, AT_SYMLINK_NOFOLLOW) == 0)
      throw OutputError("cannot read " + path.string() + ": it is " + file_kind(status.st_mode));
    throw OutputError("cannot read " + path.string() + ": " + std::strerror(error));
  }
  struct stat status {};
  const bool known = ::fstat(descriptor, &status) == 0;
  if (!known || !S_ISREG(status.st_mode)) {
    const std::string what = known ? "it is " + file_kind(status.st_mode) : system_reason();
    ::close(descriptor);
    throw OutputError("cannot read " + path.string() + ": " + what + ", where nonsep keeps a file of its own");
  }
  ::fcntl(descriptor, F_SETFL, 0);  // a regular file: plain blocking reads
  return descriptor;
}

int open_regular_file_for_writing(const std::filesystem::path& path, int flags, const std::string& verb) {
  const FileLocation location(path);
  const int descriptor =
      ::openat(location.folder(), location.name(), flags | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (descriptor < 0) {
    const int error = errno;
    struct stat status {};
    if ((error == ENXIO || error == ELOOP) &&
        ::fstatat(location.folder(), location.name(), &status, AT_SYMLINK_NOFOLLOW) == 0)
      throw OutputError(verb + path.string() + ": it is " + file_kind(status.st_mode));
    throw OutputError(verb + path.string() + ": " + std::strerror(error));
  }
  struct stat status {};
  if (::fstat(descriptor, &status) != 0 || !S_ISREG(status.st_mode)) {
    const std::string what = file_kind(status.st_mode);
    ::close(descriptor);
    throw OutputError(verb + path.string() + ": it is " + what);
  }
  ::fcntl(descriptor, F_SETFL, flags & O_APPEND);  // a regular file: plain blocking writes
  return descriptor;
}

std::optional<std::string> read_regular_file(const std::filesystem::path& path, std::size_t limit) {
  const int descriptor = open_regular_file(path);
  if (descriptor < 0) return std::nullopt;
  std::string text;
  char buffer[1 << 16];
  while (text.size() < limit) {
    const ssize_t got = ::read(descriptor, buffer, std::min(sizeof buffer, limit - text.size()));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const std::string reason = system_reason();
      ::close(descriptor);
      throw OutputError("cannot read " + path.string() + ": " + reason);
    }
    if (got == 0) break;
    text.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(descriptor);
  return text;
}

namespace {

// ".NAME.tmp-" and six random letters or digits.
std::string temporary_name(const std::string& name) {
  static constexpr char letters[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  thread_local std::mt19937_64 random(std::random_device{}());
  std::string text = "." + name + ".tmp-";
  for (int i = 0; i < 6; ++i) text += letters[random() % (sizeof letters - 1)];
  return text;
}

}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& path) : path_(path) {
  const FileLocation location(path);
  folder_ = location.folder() == AT_FDCWD ? AT_FDCWD : ::dup(location.folder());
  const std::filesystem::path name = location.name();
  // An unpredictable name, created exclusively (O_CREAT | O_EXCL, which also refuses a symbolic link planted there),
  // so that nothing else can be made to receive the text; in the folder's descriptor when the folder is held.
  int descriptor = -1;
  for (int attempt = 0; attempt < 100 && descriptor < 0; ++attempt) {
    temporary_name_ = (name.parent_path() / temporary_name(name.filename().string())).string();
    descriptor = ::openat(folder_, temporary_name_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (descriptor < 0 && errno != EEXIST) break;
  }
  temporary_ = path.parent_path() / std::filesystem::path(temporary_name_).filename();
  if (descriptor < 0) {
    const int error = errno;
    if (folder_ != AT_FDCWD) ::close(folder_);
    const auto folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
    if (error == EACCES || error == EROFS || error == EPERM)
      throw OutputError("the folder " + folder.string() + " is not writable (" + std::strerror(error) + "), so " +
                        path.filename().string() + " cannot be written there");
    throw OutputError("cannot create a temporary file for " + path.string() + ": " + std::strerror(error));
  }
  ::fchmod(descriptor, 0644);
  file_ = ::fdopen(descriptor, "wb");
  if (!file_) {
    const std::string reason = system_reason();
    ::close(descriptor);
    discard();
    throw OutputError("cannot open " + temporary_.string() + ": " + reason);
  }
}

void AtomicFile::discard() {
  ::unlinkat(folder_, temporary_name_.c_str(), 0);
  if (folder_ != AT_FDCWD) ::close(folder_);
  folder_ = AT_FDCWD;
}

AtomicFile::~AtomicFile() {
  if (!file_) return;
  std::fclose(file_);
  discard();
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
  if (!written || !closed) {
    discard();
    throw OutputError("cannot write " + temporary_.string() + ": " + reason);
  }
  const std::string name = (std::filesystem::path(temporary_name_).parent_path() / path_.filename()).string();
  if (::renameat(folder_, temporary_name_.c_str(), folder_, name.c_str()) != 0) {
    const std::string rename_reason = system_reason();
    discard();
    throw OutputError("cannot rename " + temporary_.string() + " to " + path_.string() + ": " + rename_reason);
  }
  if (folder_ != AT_FDCWD) ::close(folder_);
  folder_ = AT_FDCWD;
}

void remove_file(const std::filesystem::path& path) {
  const FileLocation location(path);
  ::unlinkat(location.folder(), location.name(), 0);
}

void write_file_atomically(const std::filesystem::path& path, const std::string& content) {
  AtomicFile file(path);
  file.write(content);
  file.commit();
}

}  // namespace nonsep::host
