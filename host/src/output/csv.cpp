#include "nonsep/host/output/csv.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/files.hpp"

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
  descriptor_ = ::open(path_.c_str(), flags | O_WRONLY | O_CLOEXEC | O_NOFOLLOW, 0644);  // never through a link
  if (descriptor_ < 0)
    throw OutputError("cannot " + std::string(flags & O_TRUNC ? "create " : "open ") + path_.string() + ": " +
                      std::strerror(errno));
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
  std::error_code error;
  const auto existing = std::filesystem::file_size(path, error);
  if (error) throw OutputError("cannot resume " + path.string() + ": " + error.message());
  if (existing < size)
    throw OutputError("cannot resume " + path.string() + ": it has " + std::to_string(existing) +
                      " bytes, fewer than the " + std::to_string(size) + " the checkpoint recorded");
  if (file_content_hash(path, size) != prefix_hash)
    throw OutputError("cannot resume " + path.string() + ": its first " + std::to_string(size) +
                      " bytes are not the ones the checkpoint recorded (another run wrote into this folder, or the "
                      "file was edited); run with --force to start over");
  std::filesystem::resize_file(path, size, error);
  if (error) throw OutputError("cannot resume " + path.string() + ": " + error.message());
  open(O_APPEND);
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
      flushed_size_ += done;
      flushed_hash_ = content_hash(std::string_view(buffer_.data(), done), flushed_hash_);
      buffer_.clear();
      throw OutputError("cannot write " + path_.string() + ": " + reason);
    }
    done += static_cast<std::size_t>(written);
  }
  flushed_size_ += done;
  flushed_hash_ = content_hash(buffer_, flushed_hash_);
  buffer_.clear();
}

}  // namespace nonsep::host
