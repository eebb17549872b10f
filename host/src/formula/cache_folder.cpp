// The formula cache's folder and its files, through descriptors (cache_folder.hpp).
#include "nonsep/host/formula/cache_folder.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

#include "nonsep/host/formula/compiler_process.hpp"
#include "nonsep/host/output/content_hash.hpp"

namespace nonsep::host::formula {

namespace fs = std::filesystem;

namespace {

std::string reason() { return std::strerror(errno); }

fs::path fallback_directory() { return fs::temp_directory_path() / ("nonsep-cache-" + std::to_string(::getuid())); }

// What makes the folder open at `descriptor` unsafe to hold code run by this user, or nothing.
std::optional<std::string> unsafe(int descriptor) {
  struct stat status = {};
  if (::fstat(descriptor, &status) != 0) return "cannot be examined: " + reason();
  if (!S_ISDIR(status.st_mode)) return std::string("is not a folder");
  if (status.st_uid != ::geteuid())
    return "is owned by user " + std::to_string(status.st_uid) + ", not by this user (" + std::to_string(::geteuid()) +
           ")";
  if ((status.st_mode & (S_IWGRP | S_IWOTH)) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(status.st_mode & 07777));
    return std::string("is writable by ") + ((status.st_mode & S_IWOTH) != 0 ? "others" : "its group") + " (mode " +
           mode + ")";
  }
  return std::nullopt;
}

// Why `name` in the folder `at` could not be opened as a folder without following a link.
std::string not_a_folder(int at, const char* name) {
  struct stat status = {};
  if (::fstatat(at, name, &status, AT_SYMLINK_NOFOLLOW) == 0 && S_ISLNK(status.st_mode)) return "is a symbolic link";
  return "is not a folder";
}

[[noreturn]] void refuse(const fs::path& folder, const std::string& why) {
  throw FormulaCompileError("the cache folder " + folder.string() + " " + why +
                            ": someone else could put code there that nonsep would load; remove it, or set "
                            "NONSEP_CACHE_DIR to a folder only you can write (docs/trust-model.md)");
}

// Whether a file can be created in the folder at `descriptor`.
bool writable(int descriptor) {
  const std::string probe = ".write-probe-" + std::to_string(::getpid());
  const int file = ::openat(descriptor, probe.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (file < 0) return false;
  ::close(file);
  ::unlinkat(descriptor, probe.c_str(), 0);
  return true;
}

// formula/ under the root folder open at `root` (created with mode 0700), checked; -1 when it cannot be created
// or written (a root where this user may not write).
int open_formula_folder(int root, const fs::path& shown) {
  if (::mkdirat(root, "formula", 0700) != 0 && errno != EEXIST) return -1;
  const int descriptor = ::openat(root, "formula", O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (descriptor < 0) {
    if (errno == ELOOP || errno == ENOTDIR) refuse(shown, not_a_folder(root, "formula"));
    return -1;
  }
  if (const auto why = unsafe(descriptor)) {
    ::close(descriptor);
    refuse(shown, *why);
  }
  if (!writable(descriptor)) {
    ::close(descriptor);
    return -1;
  }
  return descriptor;
}

}  // namespace

fs::path cache_directory() {
  if (const char* chosen = std::getenv("NONSEP_CACHE_DIR"); chosen && *chosen) return chosen;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute())
    return fs::path(xdg) / "nonsep";
  if (const char* home = std::getenv("HOME"); home && *home) return fs::path(home) / ".cache" / "nonsep";
  return fallback_directory();
}

CacheFolder CacheFolder::open(const std::function<void(const std::string&)>& say) {
  const fs::path chosen = cache_directory();
  const fs::path fallback = fallback_directory();
  if (chosen != fallback) {
    std::error_code error;
    fs::create_directories(chosen, error);
    const int root = ::open(chosen.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (root >= 0) {
      const int folder = open_formula_folder(root, chosen / "formula");
      ::close(root);
      if (folder >= 0) return CacheFolder(chosen / "formula", folder);
    }
    say("the cache folder " + chosen.string() + " is not writable; using " + fallback.string() +
        " (set NONSEP_CACHE_DIR to choose another)");
  }
  if (::mkdir(fallback.c_str(), 0700) != 0 && errno != EEXIST)
    throw FormulaCompileError("cannot create the cache folder " + fallback.string() + ": " + reason() +
                              "; set NONSEP_CACHE_DIR to a writable folder");
  const int root = ::open(fallback.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (root < 0) {
    if (errno == ELOOP || errno == ENOTDIR) refuse(fallback, not_a_folder(AT_FDCWD, fallback.c_str()));
    throw FormulaCompileError("cannot open the cache folder " + fallback.string() + ": " + reason());
  }
  if (const auto why = unsafe(root)) {
    ::close(root);
    refuse(fallback, *why);
  }
  const int folder = open_formula_folder(root, fallback / "formula");
  ::close(root);
  if (folder < 0)
    throw FormulaCompileError("neither the cache folder " + chosen.string() + " nor " + fallback.string() +
                              " is writable: set NONSEP_CACHE_DIR to a writable folder");
  return CacheFolder(fallback / "formula", folder);
}

CacheFolder::CacheFolder(CacheFolder&& other) noexcept
    : path_(std::move(other.path_)), descriptor_(std::exchange(other.descriptor_, -1)) {}

CacheFolder::~CacheFolder() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

int CacheFolder::open_folder(const std::string& name) const {
  return ::openat(descriptor_, name.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
}

void CacheFolder::make_folder(const std::string& name) const {
  if (::mkdirat(descriptor_, name.c_str(), 0700) != 0)
    throw FormulaCompileError("cannot create the folder " + (path_ / name).string() + ": " + reason());
}

bool CacheFolder::rename(const std::string& from, const std::string& to) const {
  return ::renameat(descriptor_, from.c_str(), descriptor_, to.c_str()) == 0;
}

void CacheFolder::remove(const std::string& name) const {
  if (::unlinkat(descriptor_, name.c_str(), 0) == 0 || errno == ENOENT) return;
  // A folder: moved aside under a fresh name first, so that what is removed by path is what was named here.
  const std::string aside = ".stale-" + std::to_string(::getpid()) + "-" +
                            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count());
  if (!rename(name, aside)) return;
  std::error_code error;
  fs::remove_all(path_ / aside, error);
}

CacheLock::CacheLock(const CacheFolder& folder, const std::string& name, bool wait) {
  const int flags = O_RDWR | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC;
  for (int attempt = 0; attempt < 2 && descriptor_ < 0; ++attempt) {
    descriptor_ = ::openat(folder.descriptor(), name.c_str(), flags | O_CREAT, 0600);
    struct stat status = {};
    if (descriptor_ >= 0 && ::fstat(descriptor_, &status) == 0 && S_ISREG(status.st_mode)) break;
    if (descriptor_ >= 0) ::close(descriptor_);
    descriptor_ = -1;
    // A link, FIFO or device planted at the lock's name: removed, never followed or opened again.
    if (::unlinkat(folder.descriptor(), name.c_str(), 0) != 0 && errno != ENOENT) break;
  }
  if (descriptor_ < 0)
    throw FormulaCompileError("cannot create the lock file " + (folder.path() / name).string() + ": " + reason());
  int locked;
  while ((locked = ::flock(descriptor_, wait ? LOCK_EX : LOCK_EX | LOCK_NB)) != 0 && errno == EINTR) {
  }
  if (locked != 0 && (wait || errno != EWOULDBLOCK))
    throw FormulaCompileError("cannot lock " + (folder.path() / name).string() + ": " + reason());
  held_ = locked == 0;
}

CacheLock::~CacheLock() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

namespace {

// The descriptor of the regular file `name` in `folder`, opened without following a link or blocking; -1 else.
int open_regular(int folder, const std::string& name, struct stat& status) {
  const int descriptor = ::openat(folder, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (descriptor < 0) return -1;
  if (::fstat(descriptor, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(descriptor);
    return -1;
  }
  return descriptor;
}

}  // namespace

std::optional<std::string> read_entry_file(int folder, const std::string& name, std::size_t max_bytes) {
  struct stat status = {};
  const int descriptor = open_regular(folder, name, status);
  if (descriptor < 0) return std::nullopt;
  std::optional<std::string> text;
  if (static_cast<std::uint64_t>(status.st_size) <= max_bytes) {
    text.emplace(static_cast<std::size_t>(status.st_size), '\0');
    std::size_t done = 0;
    while (done < text->size()) {
      const ssize_t n = ::pread(descriptor, text->data() + done, text->size() - done, static_cast<off_t>(done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    if (done != text->size()) text.reset();
  }
  ::close(descriptor);
  return text;
}

OpenFile& OpenFile::operator=(OpenFile&& other) noexcept {
  if (this != &other) {
    if (descriptor_ >= 0) ::close(descriptor_);
    descriptor_ = std::exchange(other.descriptor_, -1);
  }
  return *this;
}

OpenFile::~OpenFile() {
  if (descriptor_ >= 0) ::close(descriptor_);
}

fs::path OpenFile::reopen_path() const { return fs::path("/proc/self/fd") / std::to_string(descriptor_); }

std::optional<CheckedFile> open_entry_file(int folder, const std::string& name) {
  struct stat status = {};
  OpenFile file(open_regular(folder, name, status));
  if (file.descriptor() < 0) return std::nullopt;
  const auto size = static_cast<std::uint64_t>(status.st_size);
  const auto hash = descriptor_content_hash(file.descriptor(), size);
  if (!hash) return std::nullopt;
  return CheckedFile{std::move(file), size, *hash};
}

std::optional<std::pair<std::uint64_t, std::uint64_t>> entry_file_size_and_hash(int folder, const std::string& name) {
  const auto checked = open_entry_file(folder, name);
  if (!checked) return std::nullopt;
  return std::pair{checked->size, checked->hash};
}

void write_entry_file(int folder, const std::string& name, const std::string& text, const fs::path& shown) {
  const int descriptor = ::openat(folder, name.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (descriptor < 0) throw FormulaCompileError("cannot create " + shown.string() + ": " + reason());
  std::size_t done = 0;
  int failure = 0;
  while (done < text.size() && failure == 0) {
    const ssize_t n = ::write(descriptor, text.data() + done, text.size() - done);
    if (n > 0)
      done += static_cast<std::size_t>(n);
    else if (n < 0 && errno != EINTR)
      failure = errno;
    else if (n == 0)
      failure = ENOSPC;
  }
  if (failure == 0 && ::fsync(descriptor) != 0) failure = errno;
  if (::close(descriptor) != 0 && failure == 0 && errno != EINTR) failure = errno;
  if (failure != 0)
    throw FormulaCompileError("cannot write " + shown.string() + ": " + std::strerror(failure) + " (" +
                              std::to_string(done) + " of " + std::to_string(text.size()) + " bytes written)");
}

}  // namespace nonsep::host::formula
