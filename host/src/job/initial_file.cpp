// /initial/file: initial states read from a NumPy .npy file or a CSV file (sections.hpp, read_initial_file).
//
// Both hold one state per row, q then p: row b is q0 .. q(n-1), p0 .. p(n-1) of state b, so a file of 2n columns
// gives states of dimension n.
//   .npy: a little-endian float64 array ('<f8'), C or Fortran order, of shape (states, 2n), or (2n,) for one state
//         (numpy.save(path, states)); format versions 1, 2 and 3. The header is numpy's dictionary, each of descr,
//         fortran_order and shape once (parse_npy_header: a linear scan). The shape is checked against the limits
//         before any number is read, and the file must end where the array does.
//   .csv: a header row q0,...,q(n-1),p0,...,p(n-1) (the names say the order), then one row of 2n numbers per state;
//         the last row may end without '\n', and lines may end with "\r\n". Read a row at a time (CsvReader), each
//         within max_initial_csv_columns cells of max_initial_csv_cell_bytes, checked as it is read.
// The same limits as states written in the job: at most max_initial_states states and max_initial_values numbers
// in q; every number finite. The file is opened without blocking and must be a regular file (a FIFO or a device is
// refused, never waited on). Every problem is an issue at /initial/file naming the file, and the row or byte offset.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string_view>

#include "nonsep/host/output/csv_reader.hpp"
#include "sections.hpp"

namespace nonsep::host::job_reader {

namespace {

namespace fs = std::filesystem;

const std::string file_path = "/initial/file";

struct Problem {
  std::string found, allowed;
};

const std::string npy_allowed =
    "a NumPy .npy file of a little-endian float64 array ('<f8') of shape (states, 2n), one state per row: q0..q(n-1) "
    "then p0..p(n-1) (numpy.save)";
const std::string csv_allowed =
    "a CSV file with the header q0,...,q(n-1),p0,...,p(n-1) and one row of 2n finite numbers per state";
const std::string csv_bounds = csv_allowed + ", of at most " + std::to_string(max_initial_csv_columns) +
                               " columns and " + std::to_string(max_initial_csv_cell_bytes) + " bytes per cell";

// The states of `columns` numbers per row (q then p) into `states`, or a problem when they break the limits.
std::optional<Problem> check_shape(std::size_t rows, std::size_t columns, const std::string& where) {
  if (columns == 0 || columns % 2 != 0)
    return Problem{where + " " + std::to_string(columns) + " columns",
                   "an even number of columns: q0..q(n-1) then p0..p(n-1)"};
  if (rows == 0) return Problem{where + " no state", "at least one state"};
  if (rows > max_initial_states)
    return Problem{where + " " + std::to_string(rows) + " states",
                   "at most " + std::to_string(max_initial_states) + " states"};
  if (rows > max_initial_values / (columns / 2))
    return Problem{where + " " + std::to_string(rows) + " states of dimension " + std::to_string(columns / 2),
                   "at most " + std::to_string(max_initial_values) + " numbers in q (states times dimension)"};
  return std::nullopt;
}

void store(const std::vector<double>& rows, std::size_t count, std::size_t columns, bool fortran,
           InitialStates& states) {
  const std::size_t n = columns / 2;
  states.dimension = n;
  states.count = count;
  states.q.resize(count * n);
  states.p.resize(count * n);
  for (std::size_t b = 0; b < count; ++b)
    for (std::size_t c = 0; c < columns; ++c) {
      const double x = fortran ? rows[c * count + b] : rows[b * columns + c];
      (c < n ? states.q[b * n + c] : states.p[b * n + c - n]) = x;
    }
}

// `text` quoted for a message: at most 40 characters, other than printable ASCII shown as '?'.
std::string excerpt(std::string_view text) {
  std::string shown(text.substr(0, 40));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return "'" + shown + (text.size() > 40 ? "...'" : "'");
}

// The header of a .npy file as numpy writes it and reads it (ast.literal_eval of a dict): exactly the keys descr
// (a string), fortran_order (True or False) and shape (a tuple of non-negative decimal integers), each once, in
// any order, with an optional trailing comma, then only white space. A linear scan (the header is at most 64 KiB):
// no recursion, no backtracking. The numbers of the shape are kept as written, so that a message shows them as
// they are in the file.
struct NpyHeader {
  std::string descr;
  bool fortran = false;
  std::vector<std::string> shape;
};

// `header` into `parsed`, or what is wrong with it (found) and where (the offset in the header).
std::optional<std::string> parse_npy_header(std::string_view header, NpyHeader& parsed) {
  std::size_t at = 0;
  const auto white = [&] {
    while (at < header.size() && (header[at] == ' ' || header[at] == '\t' || header[at] == '\n' || header[at] == '\r'))
      ++at;
  };
  const auto here = [&](const std::string& what) {
    return what + " at character " + std::to_string(at) + " of the header" +
           (at < header.size() ? " (" + excerpt(header.substr(at)) + ")" : " (its end)");
  };
  const auto take = [&](char c) {
    white();
    if (at < header.size() && header[at] == c) {
      ++at;
      return true;
    }
    return false;
  };
  // A Python string literal without escapes, quoted by ' or ".
  const auto string = [&](std::string& into) {
    white();
    if (at == header.size() || (header[at] != '\'' && header[at] != '"')) return false;
    const char quote = header[at];
    const std::size_t begin = ++at;
    while (at < header.size() && header[at] != quote && header[at] != '\\' && header[at] != '\n') ++at;
    if (at == header.size() || header[at] != quote) return false;
    into.assign(header.substr(begin, at - begin));
    ++at;
    return true;
  };
  if (!take('{')) return here("no '{'");
  bool descr = false, fortran = false, shape = false;
  while (!take('}')) {
    std::string key;
    white();
    const std::size_t key_at = at;
    if (!string(key)) return here("no quoted key");
    bool* seen = key == "descr" ? &descr : key == "fortran_order" ? &fortran : key == "shape" ? &shape : nullptr;
    if (!seen || *seen) {
      at = key_at;
      return here(seen ? "the key " + excerpt(key) + " a second time"
                       : "the key " + excerpt(key) + ", not one of 'descr', 'fortran_order' and 'shape',");
    }
    *seen = true;
    if (!take(':')) return here("no ':'");
    white();
    if (key == "descr") {
      if (!string(parsed.descr)) return here("a descr that is not a quoted string without escapes");
    } else if (key == "fortran_order") {
      if (header.substr(at, 4) == "True") {
        parsed.fortran = true;
        at += 4;
      } else if (header.substr(at, 5) == "False") {
        parsed.fortran = false;
        at += 5;
      } else {
        return here("a fortran_order that is neither True nor False");
      }
    } else {
      if (!take('(')) return here("a shape that is not a tuple");
      parsed.shape.clear();
      bool comma = false;  // a tuple of one number needs its trailing comma: (3) is 3, not a tuple
      while (!take(')')) {
        white();
        const std::size_t begin = at;
        while (at < header.size() && header[at] >= '0' && header[at] <= '9') ++at;
        const std::string_view digits = header.substr(begin, at - begin);
        if (digits.empty() || (digits.size() > 1 && digits.front() == '0'))
          return here("a shape that is not a tuple of decimal integers");
        parsed.shape.emplace_back(digits);
        comma = take(',');
        if (!comma && !take(')')) return here("a shape that is not a tuple of decimal integers");
        if (!comma) break;
      }
      if (parsed.shape.size() == 1 && !comma) return here("a shape that is not a tuple (a number in parentheses)");
    }
    if (!take(',')) {
      if (!take('}')) return here("no ',' or '}'");
      break;
    }
  }
  white();
  if (at != header.size()) return here("more after the dictionary");
  if (!descr || !fortran || !shape) return here("a dictionary without all of 'descr', 'fortran_order' and 'shape'");
  return std::nullopt;
}

std::optional<Problem> read_npy(int descriptor, std::uint64_t size, const std::string& shown, InitialStates& states) {
  const auto read_at = [&](void* into, std::size_t bytes, std::uint64_t offset) {
    auto* target = static_cast<char*>(into);
    for (std::size_t done = 0; done < bytes;) {
      const ssize_t n = ::pread(descriptor, target + done, bytes - done, static_cast<off_t>(offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) return false;
      done += static_cast<std::size_t>(n);
    }
    return true;
  };
  unsigned char prefix[12] = {};
  if (size < 10 || !read_at(prefix, 10, 0) || std::memcmp(prefix, "\x93NUMPY", 6) != 0)
    return Problem{shown + ", which does not begin as a .npy file (\\x93NUMPY)", npy_allowed};
  const int major = prefix[6];
  if (major < 1 || major > 3)
    return Problem{shown + ", a .npy file of format version " + std::to_string(major), npy_allowed};
  std::uint64_t header_length = prefix[8] | (prefix[9] << 8);
  std::uint64_t header_start = 10;
  if (major >= 2) {
    if (size < 12 || !read_at(prefix, 12, 0)) return Problem{shown + ", a .npy file cut short", npy_allowed};
    header_length =
        prefix[8] | (prefix[9] << 8) | (std::uint64_t{prefix[10]} << 16) | (std::uint64_t{prefix[11]} << 24);
    header_start = 12;
  }
  if (header_length > 65536 || header_start + header_length > size)
    return Problem{shown + ", a .npy file whose header of " + std::to_string(header_length) + " bytes does not fit",
                   npy_allowed};
  std::string header(static_cast<std::size_t>(header_length), '\0');
  if (!read_at(header.data(), header.size(), header_start))
    return Problem{shown + ", which cannot be read", npy_allowed};
  NpyHeader parsed;
  if (const auto problem = parse_npy_header(header, parsed))
    return Problem{shown + ", a .npy header that is not numpy's dictionary: " + *problem, npy_allowed};
  if (parsed.descr != "<f8") return Problem{shown + ", an array of dtype " + excerpt(parsed.descr), npy_allowed};
  if (parsed.shape.empty()) return Problem{shown + ", an array of shape () (a single number)", npy_allowed};
  if (parsed.shape.size() > 2) return Problem{shown + ", an array of more than two dimensions", npy_allowed};
  // The shape's numbers, each at most a limit (larger ones are shown as written in the file).
  const std::uint64_t limit = std::max<std::uint64_t>(max_initial_states, 2 * max_initial_values);
  const auto number = [&](const std::string& digits) {
    std::uint64_t value = 0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    return error == std::errc() && end == digits.data() + digits.size() && value <= limit ? value : limit + 1;
  };
  const bool one_state = parsed.shape.size() == 1;
  const std::uint64_t rows = one_state ? 1 : number(parsed.shape[0]);
  const std::uint64_t columns = number(parsed.shape.back());
  if (rows > max_initial_states || columns > 2 * max_initial_values)
    return Problem{shown + " of shape (" + parsed.shape[0] + (one_state ? "," : ", " + parsed.shape[1]) + ")",
                   "at most " + std::to_string(max_initial_states) + " states and " +
                       std::to_string(max_initial_values) + " numbers in q"};
  if (auto problem = check_shape(static_cast<std::size_t>(rows), static_cast<std::size_t>(columns), shown + ":"))
    return problem;
  const std::uint64_t data_start = header_start + header_length;
  const std::uint64_t data_bytes = rows * columns * sizeof(double);
  if (size != data_start + data_bytes)
    return Problem{shown + ", " + std::to_string(size) + " bytes where its header says " +
                       std::to_string(data_start + data_bytes) + " (" + std::to_string(rows) + " x " +
                       std::to_string(columns) + " numbers after a header of " + std::to_string(data_start) + ")",
                   npy_allowed};
  std::vector<double> values(static_cast<std::size_t>(rows * columns));
  if (!read_at(values.data(), static_cast<std::size_t>(data_bytes), data_start))
    return Problem{shown + ", which cannot be read", npy_allowed};
  static_assert(std::endian::native == std::endian::little, "the .npy reader takes '<f8' as native doubles");
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      return Problem{
          shown + ": a number that is not finite at byte offset " + std::to_string(data_start + i * sizeof(double)),
          "finite numbers"};
  store(values, static_cast<std::size_t>(rows), static_cast<std::size_t>(columns), parsed.fortran, states);
  return std::nullopt;
}

std::optional<Problem> read_csv(int descriptor, const std::string& shown, InitialStates& states) {
  // Each row is read within its bounds: the header at most max_initial_csv_columns cells, a state's row as many as
  // the header, every cell at most max_initial_csv_cell_bytes.
  CsvReader reader("/proc/self/fd/" + std::to_string(descriptor), "(the initial states)",
                   {.hand_written = true,
                    .max_cells = max_initial_csv_columns,
                    .max_cell_bytes = max_initial_csv_cell_bytes,
                    .name = shown});
  std::vector<std::string> cells;
  if (!reader.next(cells)) return Problem{shown + ", which has no header row", csv_allowed};
  const std::size_t columns = cells.size();
  reader.rules().max_cells = columns;
  if (auto problem = check_shape(1, columns, shown + ": a header of")) return problem;
  const std::size_t n = columns / 2;
  for (std::size_t c = 0; c < columns; ++c) {
    const std::string expected = (c < n ? "q" : "p") + std::to_string(c < n ? c : c - n);
    if (cells[c] != expected)
      return Problem{shown + ": column " + std::to_string(c + 1) + " of the header is \"" + cells[c] + "\"",
                     "\"" + expected + "\" there: " + csv_allowed};
  }
  std::vector<double> values;
  std::size_t rows = 0;
  while (reader.next(cells)) {
    const std::string row = shown + ":" + std::to_string(reader.line());
    if (cells.size() != columns)
      return Problem{row + ": " + std::to_string(cells.size()) + " cells", std::to_string(columns) + ", as the header"};
    if (auto problem = check_shape(rows + 1, columns, row + ":")) return problem;
    for (std::size_t c = 0; c < columns; ++c) {
      double x = 0.0;
      const std::string& text = cells[c];
      const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), x);
      if (error != std::errc() || end != text.data() + text.size() || text.empty() || !std::isfinite(x))
        return Problem{row + ": \"" + text + "\" in column " + std::to_string(c + 1), "a finite number"};
      values.push_back(x);
    }
    ++rows;
  }
  if (auto problem = check_shape(rows, columns, shown + ":")) return problem;
  store(values, rows, columns, false, states);
  return std::nullopt;
}

}  // namespace

void read_initial_file(Checker& check, const json& initial, const fs::path& directory, InitialStates& states) {
  const KeyReader keys(check, initial, "/initial", initial_file_keys(), "");
  const std::string what = allowed_text(initial_file_keys()["file"]);
  const auto name = keys.string("file");
  if (!name) return;
  const fs::path path = fs::path(*name).is_absolute() ? fs::path(*name) : directory / *name;
  const std::string extension = path.extension().string();
  if (extension != ".npy" && extension != ".csv") {
    check.issue(file_path, "\"" + *name + "\", neither .npy nor .csv", what);
    return;
  }
  const std::string shown = "\"" + *name + "\" (" + path.string() + ")";
  const int descriptor = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  struct stat status = {};
  std::optional<Problem> problem;
  if (descriptor < 0)
    problem = Problem{shown + ", which cannot be opened: " + std::strerror(errno), what};
  else if (::fstat(descriptor, &status) != 0 || !S_ISREG(status.st_mode))
    problem = Problem{shown + ", which is not a regular file", what};
  else if (extension == ".npy")
    problem = read_npy(descriptor, static_cast<std::uint64_t>(status.st_size), shown, states);
  else
    try {
      problem = read_csv(descriptor, shown, states);
    } catch (const std::exception& error) {
      problem = Problem{error.what(), csv_bounds};  // the reader's messages begin with `shown`
    }
  if (descriptor >= 0) ::close(descriptor);
  if (problem) {
    check.issue(file_path, problem->found, problem->allowed);
    states = InitialStates();
    states.shape = "file";
  }
}

}  // namespace nonsep::host::job_reader
