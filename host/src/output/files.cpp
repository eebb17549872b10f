#include "nonsep/host/output/files.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>


namespace nonsep::host {

namespace {
std::string system_reason() { return std::strerror(errno); }
}  // namespace

AtomicFile::AtomicFile(const std::filesystem::path& path) : path_(path) {
  // An unpredictable name, created exclusively (mkstemp: O_CREAT | O_EXCL, which also refuses a symbolic link
  // planted there), so that nothing else can be made to receive the text.
  std::string pattern = (path.parent_path() / ("." + path.filename().string() + ".tmp-XXXXXX")).string();
  const int descriptor = ::mkstemp(pattern.data());
  if (descriptor < 0) throw OutputError("cannot create a temporary file for " + path.string() + ": " + system_reason());
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
