#include "nonsep/host/output/csv_reader.hpp"

#include <cstdio>
#include <utility>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/held_folder.hpp"

namespace nonsep::host {

CsvReader::CsvReader(const std::filesystem::path& path, std::string purpose, Rules rules)
    : path_(path),
      purpose_(std::move(purpose)),
      rules_(std::move(rules)),
      in_(held_path(path), std::ios::binary),
      buffer_(1 << 20) {
  if (rules_.name.empty()) rules_.name = path_.string();
  if (!in_) throw OutputError("cannot read " + rules_.name + " " + purpose_);
}

void CsvReader::refuse(std::uint64_t line, const std::string& what) const {
  throw OutputError(rules_.name + ":" + std::to_string(line) + ": " + what);
}

bool CsvReader::next(std::vector<std::string>& cells) {
  std::size_t count = 0;
  text_.clear();
  offsets_.clear();
  const auto start_cell = [&] {
    if (count == rules_.max_cells) refuse(line_, "a row of more than " + std::to_string(rules_.max_cells) + " cells");
    if (count == cells.size()) cells.emplace_back();
    cells[count++].clear();
    offsets_.push_back(text_.size());
  };
  const auto check_cell = [&] {
    if (cells[count - 1].size() > rules_.max_cell_bytes)
      refuse(line_,
             "cell " + std::to_string(count) + ", longer than " + std::to_string(rules_.max_cell_bytes) + " bytes");
  };
  start_cell();
  bool quoted = false;
  const std::uint64_t first_line = line_;
  for (int c; (c = get()) != EOF;) {
    if (c == '\r' && !quoted && rules_.hand_written && peek() == '\n') continue;
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
        check_cell();
      } else if (peek() == '"') {
        text_ += static_cast<char>(get());
        cells[count - 1] += '"';
        check_cell();
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      start_cell();
    } else if (c == '\r') {
      // Not a line end's (the check above looked ahead, which may have refilled the buffer): one character.
      cells[count - 1] += '\r';
      check_cell();
    } else {
      // The rest of an unquoted cell in the buffer at once: most cells are numbers with no quote.
      const std::size_t begin = next_ - 1;
      while (next_ < end_ && buffer_[next_] != ',' && buffer_[next_] != '\n' && buffer_[next_] != '"' &&
             buffer_[next_] != '\r')
        ++next_;
      cells[count - 1].append(buffer_.data() + begin, next_ - begin);
      text_.append(buffer_.data() + begin + 1, next_ - begin - 1);
      check_cell();
    }
  }
  if (quoted) refuse(first_line, "a quoted cell is not closed");
  if (!rules_.hand_written || (count == 1 && text_.empty())) return false;
  ++line_;  // the last line, without '\n'
  cells.resize(count);
  return true;
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
  if (in_.bad()) throw OutputError("cannot read " + rules_.name + " " + purpose_);
}

}  // namespace nonsep::host
