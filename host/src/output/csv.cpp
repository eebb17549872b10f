#include "nonsep/host/output/csv.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/held_folder.hpp"

namespace nonsep::host {

namespace {
constexpr std::size_t buffer_capacity = 1 << 16;
}  // namespace

void append_csv_text(std::string& row, std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) {
    row += text;
    return;
  }
  row += '"';
  for (char c : text) {
    if (c == '"') row += '"';
    row += c;
  }
  row += '"';
}

void CsvAppender::open(int flags) {
  descriptor_ =
      open_regular_file_for_writing(path_, flags | O_WRONLY, flags & O_TRUNC ? "cannot create " : "cannot open ");
  buffer_.reserve(buffer_capacity + 4096);
}

CsvAppender::CsvAppender(const std::filesystem::path& path, std::string_view header)
    : path_(path), flushed_hash_(content_hash_start) {
  open(O_CREAT | O_TRUNC);
  buffer_ += header;
  end_row();
}

CsvAppender::CsvAppender(const std::filesystem::path& path, std::uint64_t size, std::uint64_t prefix_hash)
    : path_(path), flushed_size_(size), flushed_hash_(prefix_hash) {
  // Everything through one descriptor opened without following links: a trajectory.csv replaced by a link to a
  // file elsewhere is refused before anything is read or cut, not truncated through the link.
  const FileLocation location(path);
  descriptor_ = ::openat(location.folder(), location.name(), O_RDWR | O_APPEND | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (descriptor_ < 0)
    throw OutputError("cannot resume " + path.string() + ": " +
                      (errno == ELOOP ? std::string("it is a symbolic link") : std::strerror(errno)));
  const auto refuse = [&](const std::string& reason) {
    ::close(descriptor_);
    descriptor_ = -1;
    throw OutputError("cannot resume " + path.string() + ": " + reason);
  };
  struct stat status {};
  if (::fstat(descriptor_, &status) != 0) refuse(std::strerror(errno));
  if (!S_ISREG(status.st_mode)) refuse("it is " + file_kind(status.st_mode) + ", not a regular file");
  ::fcntl(descriptor_, F_SETFL, O_APPEND);
  if (static_cast<std::uint64_t>(status.st_size) < size)
    refuse("it has " + std::to_string(status.st_size) + " bytes, fewer than the " + std::to_string(size) +
           " the checkpoint recorded");
  if (descriptor_content_hash(descriptor_, size) != prefix_hash)
    refuse("its first " + std::to_string(size) +
           " bytes are not the ones the checkpoint recorded (another run wrote into this folder, or the file was "
           "edited); run with --force to start over");
  if (::ftruncate(descriptor_, static_cast<off_t>(size)) != 0) refuse(std::strerror(errno));
  buffer_.reserve(buffer_capacity + 4096);
}

CsvAppender::~CsvAppender() {
  try {
    flush();
  } catch (const OutputError&) {
  }
  ::close(descriptor_);
}

void CsvAppender::end_row() {
  buffer_ += '\n';
  if (buffer_.size() >= buffer_capacity) flush();
}

void CsvAppender::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t written = ::write(descriptor_, buffer_.data() + done, buffer_.size() - done);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) {
      const std::string reason = written < 0 ? std::strerror(errno) : "nothing was written";
      // A full disk or a file size limit: keep whole rows only. The file is cut back to the end of the last row
      // this flush wrote completely, so that no reader (and no resume) sees a row cut short.
      const std::size_t last_newline = done ? buffer_.rfind('\n', done - 1) : std::string::npos;
      const std::size_t whole = last_newline == std::string::npos ? 0 : last_newline + 1;
      const std::string cut = ::ftruncate(descriptor_, static_cast<off_t>(flushed_size_ + whole)) == 0
                                  ? "; the file ends at its last whole row"
                                  : "; the last row may be cut short (" + std::string(std::strerror(errno)) + ")";
      flushed_size_ += whole;
      flushed_hash_ = content_hash(std::string_view(buffer_.data(), whole), flushed_hash_);
      buffer_.clear();
      throw OutputError("cannot write " + path_.string() + ": " + reason + cut);
    }
    done += static_cast<std::size_t>(written);
  }
  flushed_size_ += done;
  flushed_hash_ = content_hash(buffer_, flushed_hash_);
  buffer_.clear();
}

nlohmann::json csv_checkpoint_state(CsvAppender& file) {
  file.flush();
  return {{"bytes", file.flushed_size()}, {"content_hash", content_hash_hex(file.flushed_hash())}};
}

namespace detail {

CsvResumePoint csv_resume_point(const nlohmann::json& state, const std::filesystem::path& path) {
  CsvResumePoint point;
  if (!state.is_object() || !state.contains("bytes") || !state["bytes"].is_number_unsigned()) {
    point.problem = "no byte count";
    return point;
  }
  point.bytes = state["bytes"].get<std::uint64_t>();
  const nlohmann::json& hash = state.contains("content_hash") ? state["content_hash"] : nlohmann::json();
  const std::string* digits = hash.is_string() ? &hash.get_ref<const std::string&>() : nullptr;
  if (!digits || digits->size() != 16 ||
      std::from_chars(digits->data(), digits->data() + 16, point.content_hash, 16).ec != std::errc())
    point.problem = "no content hash of " + path.filename().string();
  return point;
}

}  // namespace detail

}  // namespace nonsep::host
