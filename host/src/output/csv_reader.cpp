#include "nonsep/host/output/csv_reader.hpp"

#include <cstdio>
#include <utility>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/held_folder.hpp"

namespace nonsep::host {

CsvReader::CsvReader(const std::filesystem::path& path, std::string purpose)
    : path_(path), purpose_(std::move(purpose)), in_(held_path(path), std::ios::binary), buffer_(1 << 20) {
  if (!in_) throw OutputError("cannot read " + path.string() + " " + purpose_);
}

bool CsvReader::next(std::vector<std::string>& cells) {
  std::size_t count = 0;
  text_.clear();
  offsets_.clear();
  const auto start_cell = [&] {
    if (count == cells.size()) cells.emplace_back();
    cells[count++].clear();
    offsets_.push_back(text_.size());
  };
  start_cell();
  bool quoted = false;
  const std::uint64_t first_line = line_;
  for (int c; (c = get()) != EOF;) {
    if (c == '\n' && !quoted) {
      ++line_;
      cells.resize(count);
      return true;
    }
    text_ += static_cast<char>(c);
    if (quoted) {
      if (c != '"') {
        line_ += c == '\n';
        cells[count - 1] += static_cast<char>(c);
      } else if (peek() == '"') {
        text_ += static_cast<char>(get());
        cells[count - 1] += '"';
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      start_cell();
    } else {
      // The rest of an unquoted cell in the buffer at once: most cells are numbers with no quote.
      const std::size_t begin = next_ - 1;
      while (next_ < end_ && buffer_[next_] != ',' && buffer_[next_] != '\n' && buffer_[next_] != '"') ++next_;
      cells[count - 1].append(buffer_.data() + begin, next_ - begin);
      text_.append(buffer_.data() + begin + 1, next_ - begin - 1);
    }
  }
  if (quoted) throw OutputError(path_.string() + ":" + std::to_string(first_line) + ": a quoted cell is not closed");
  return false;
}

int CsvReader::peek() {
  if (next_ == end_) refill();
  return next_ == end_ ? EOF : static_cast<unsigned char>(buffer_[next_]);
}

int CsvReader::get() {
  const int c = peek();
  if (c != EOF) ++next_;
  return c;
}

void CsvReader::refill() {
  in_.read(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  next_ = 0;
  end_ = static_cast<std::size_t>(in_.gcount());
  if (in_.bad()) throw OutputError("cannot read " + path_.string() + " " + purpose_);
}

}  // namespace nonsep::host
