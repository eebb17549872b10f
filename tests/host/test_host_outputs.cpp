// The output writers in-process: the number format, the CSV writer (layout, quoting, buffering on whole rows,
// resuming), the CSV reader and atomic replacement.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/csv.hpp"
#include "nonsep/host/output/csv_reader.hpp"

namespace test_host_outputs {

using namespace nonsep::host;
using nonsep::host_testing::read_csv;
using nonsep::host_testing::read_text;
using nonsep::host_testing::TemporaryFolder;

TEST_CASE("numbers are written in the shortest text that reads back to the same double") {
  CHECK(format_number(0.1) == "0.1");
  CHECK(format_number(-2.0) == "-2");
  CHECK(format_number(1e-300) == "1e-300");
  for (const double x : {0.3863765573361232, -1.5723027555148124, 1.0 / 3.0, 6.02214076e23, 5e-324,
                         std::numeric_limits<double>::max()}) {
    const std::string text = format_number(x);
    double back = 0.0;
    std::from_chars(text.data(), text.data() + text.size(), back);
    CHECK(back == x);
  }
}

TEST_CASE("ordinals in messages: 1st, 2nd, 3rd, 4th, 11th to 13th, 21st, 102nd, 111th") {
  using nonsep::host::ordinal;
  CHECK(ordinal(1) == "1st");
  CHECK(ordinal(2) == "2nd");
  CHECK(ordinal(3) == "3rd");
  CHECK(ordinal(4) == "4th");
  CHECK(ordinal(11) == "11th");
  CHECK(ordinal(12) == "12th");
  CHECK(ordinal(13) == "13th");
  CHECK(ordinal(21) == "21st");
  CHECK(ordinal(102) == "102nd");
  CHECK(ordinal(111) == "111th");
  CHECK(ordinal(0) == "0th");
}

TEST_CASE("CsvAppender: header, rows of cells, empty cells for unknown numbers, quoted text where needed") {
  TemporaryFolder folder;
  const auto path = folder / "table.csv";
  {
    CsvAppender file(path, "a,b,c");
    append_number(file.row(), 0.125);
    file.row() += ',';
    append_csv_number(file.row(), std::nullopt);
    file.row() += ',';
    append_csv_text(file.row(), "plain");
    file.end_row();
    append_csv_number(file.row(), -2.0);
    file.row() += ",,";
    append_csv_text(file.row(), "a \"quoted\", text");
    file.end_row();
    file.flush();
  }
  CHECK(read_text(path) == "a,b,c\n0.125,,plain\n-2,,\"a \"\"quoted\"\", text\"\n");
}

TEST_CASE("CsvAppender: rows reach the file whole, when the buffer fills and when the writer is destroyed") {
  TemporaryFolder folder;
  const auto path = folder / "trajectory.csv";
  std::size_t rows_written = 0;
  {
    CsvAppender file(path, "step,x");
    while (read_text(path).empty()) {
      file.row() += std::to_string(rows_written) + ",0.5";
      file.end_row();
      ++rows_written;
      REQUIRE(rows_written < 100000);
    }
    CHECK(rows_written > 100);  // buffered, not one write per row
    const std::string text = read_text(path);
    CHECK(text.back() == '\n');  // never part of a row
    CHECK(file.flushed_size() == text.size());
  }
  CHECK(read_csv(path).size() == rows_written + 1);
}

TEST_CASE("CsvAppender resumes a file cut back to a recorded size and content, and refuses any other file") {
  TemporaryFolder folder;
  const auto path = folder / "trajectory.csv";
  std::uint64_t size = 0, hash = 0;
  {
    CsvAppender file(path, "step");
    file.row() += "1";
    file.end_row();
    file.flush();
    size = file.flushed_size();
    hash = file.flushed_hash();
    file.row() += "2";
    file.end_row();
  }
  CHECK(hash == content_hash("step\n1\n"));
  {
    CsvAppender file(path, size, hash);
    file.row() += "3";
    file.end_row();
    file.flush();
    CHECK(file.flushed_hash() == content_hash("step\n1\n3\n"));
  }
  CHECK(read_text(path) == "step\n1\n3\n");
  CHECK_THROWS_WITH_AS(CsvAppender(path, 1000, hash), doctest::Contains("fewer than the 1000"), OutputError);
  // Same length, other bytes (another run's rows): refused, and the file is left as it was.
  write_file_atomically(path, "step\n7\n3\n");
  CHECK_THROWS_WITH_AS(CsvAppender(path, size, hash), doctest::Contains("not the ones the checkpoint recorded"),
                       OutputError);
  CHECK(read_text(path) == "step\n7\n3\n");
}

TEST_CASE("a CSV file that cannot be created is an OutputError naming the file") {
  TemporaryFolder folder;
  CHECK_THROWS_WITH_AS(CsvAppender(folder / "missing" / "trajectory.csv", "x"),
                       doctest::Contains("missing/trajectory.csv"), OutputError);
}

TEST_CASE("summary.json is replaced atomically, leaving no temporary file") {
  TemporaryFolder folder;
  const auto path = folder / "summary.json";
  write_file_atomically(path, "{\"status\": \"first\"}\n");
  write_file_atomically(path, "{\"status\": \"second\"}\n");
  CHECK(read_text(path) == "{\"status\": \"second\"}\n");
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder.path())) {
    (void)entry;
    ++files;
  }
  CHECK(files == 1);
  CHECK_THROWS_AS(write_file_atomically(folder / "missing" / "summary.json", "{}"), OutputError);
}

TEST_CASE("a folder that is not writable is named as such, not as a temporary file that cannot be created") {
  // Root writes anywhere, so the attempt runs in a child process that is not root (as user nobody when the
  // suite runs as root, as CI does) on a folder without write permission.
  const TemporaryFolder folder;
  const auto locked = folder / "locked";
  std::filesystem::create_directory(locked);
  REQUIRE(::chmod(locked.c_str(), 0555) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    if (::getuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(3);
    try {
      write_file_atomically(locked / "summary.json", "{}");
    } catch (const OutputError& e) {
      const std::string message = e.what();
      const bool named = message.find("the folder " + locked.string() + " is not writable (") != std::string::npos &&
                         message.find("summary.json cannot be written there") != std::string::npos;
      ::_exit(named ? 0 : 1);
    } catch (...) {
      ::_exit(4);
    }
    ::_exit(2);  // written: the folder was writable after all
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  ::chmod(locked.c_str(), 0755);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
}

TEST_CASE("CsvReader reads what CsvAppender writes: cells unquoted, each row's text as in the file, cut rows dropped") {
  const TemporaryFolder folder;
  {
    CsvAppender file(folder / "table.csv", "trajectory,message,t");
    file.row() += "3,";
    append_csv_text(file.row(), "x, \"y\"\nz");
    file.row() += ",0.5";
    file.end_row();
    file.row() += "4,,";
    file.end_row();
    file.flush();
  }
  const std::string written = read_text(folder / "table.csv");
  write_file_atomically(folder / "cut.csv", written + "5,partial");
  for (const char* name : {"table.csv", "cut.csv"}) {
    CAPTURE(name);
    CsvReader reader(folder / name, "to test it");
    std::vector<std::string> cells;
    REQUIRE(reader.next(cells));
    CHECK(cells == std::vector<std::string>{"trajectory", "message", "t"});
    REQUIRE(reader.next(cells));
    CHECK(cells == std::vector<std::string>{"3", "x, \"y\"\nz", "0.5"});
    CHECK(reader.text() == "3,\"x, \"\"y\"\"\nz\",0.5");
    CHECK(reader.offset(0) == 0);
    CHECK(reader.offset(1) == 2);
    CHECK(reader.text().substr(reader.offset(2)) == "0.5");
    CHECK(reader.line() == 3);
    REQUIRE(reader.next(cells));
    CHECK(cells == std::vector<std::string>{"4", "", ""});
    CHECK(reader.text() == "4,,");
    CHECK_FALSE(reader.next(cells));
  }
  write_file_atomically(folder / "open_quote.csv", "a,b\n1,\"never closed\n");
  CsvReader open_quote(folder / "open_quote.csv", "to test it");
  std::vector<std::string> cells;
  CHECK(open_quote.next(cells));
  CHECK_THROWS_WITH_AS(open_quote.next(cells), doctest::Contains("open_quote.csv:2: a quoted cell is not closed"),
                       OutputError);
  const std::string missing = "cannot read " + (folder / "missing.csv").string() + " to test it";
  CHECK_THROWS_WITH_AS(CsvReader(folder / "missing.csv", "to test it"), doctest::Contains(missing.c_str()),
                       OutputError);
}

TEST_CASE("CsvReader with Rules: a hand-written file's last line without newline and CRLF ends, bounds as it reads") {
  const TemporaryFolder folder;
  using Rows = std::vector<std::vector<std::string>>;
  std::vector<std::uint64_t> lines;
  const auto rows_of = [&](const std::string& name, const std::string& text, const CsvReader::Rules& rules) {
    write_file_atomically(folder / name, text);
    CsvReader reader(folder / name, "to test it", rules);
    Rows rows;
    lines.clear();
    for (std::vector<std::string> cells; reader.next(cells);) {
      rows.push_back(cells);
      lines.push_back(reader.line());
    }
    return rows;
  };
  CsvReader::Rules by_hand;
  by_hand.hand_written = true;
  // The last row without '\n' is a row of a file written by hand, a cut row of one written by nonsep.
  CHECK(rows_of("last.csv", "q0,p0\n2,0\n1,0", by_hand) == Rows{{"q0", "p0"}, {"2", "0"}, {"1", "0"}});
  CHECK(lines == std::vector<std::uint64_t>{1, 2, 3});
  CHECK(rows_of("last.csv", "q0,p0\n2,0\n1,0", {}) == Rows{{"q0", "p0"}, {"2", "0"}});
  CHECK(rows_of("one.csv", "q0,p0\n2,0", by_hand) == Rows{{"q0", "p0"}, {"2", "0"}});
  CHECK(rows_of("ended.csv", "q0,p0\n2,0\n", by_hand) == Rows{{"q0", "p0"}, {"2", "0"}});
  // "\r\n" ends a line; a '\r' elsewhere, or inside quotes, is the cell's.
  CHECK(rows_of("crlf.csv", "q0,p0\r\n2,\"a\r\nb\"\r\n1,x\ry\r\n", by_hand) ==
        Rows{{"q0", "p0"}, {"2", "a\r\nb"}, {"1", "x\ry"}});
  CHECK(lines == std::vector<std::uint64_t>{1, 3, 4});
  CHECK(rows_of("crlf_last.csv", "q0,p0\r\n2,0", by_hand) == Rows{{"q0", "p0"}, {"2", "0"}});
  CHECK(rows_of("crlf_nonsep.csv", "q0,p0\r\n", {}) == Rows{{"q0", "p0\r"}});
  // A '\r' that ends the file, or the reader's buffer, is the cell's (the look-ahead for '\n' found none).
  CHECK(rows_of("cr_last.csv", "q0,p0\n2,0\r", by_hand) == Rows{{"q0", "p0"}, {"2", "0\r"}});
  CHECK(rows_of("cr_only.csv", "\"a\"\r3\r", by_hand) == Rows{{"a\r3\r"}});

  // The bounds are checked as the row is read: the line is the reader's, the rest of the file is never read.
  const CsvReader::Rules bounded{.hand_written = true, .max_cells = 3, .max_cell_bytes = 4, .name = "the file"};
  std::vector<std::string> cells;
  write_file_atomically(folder / "wide.csv", "a,b,c\n1,2,3,4,5\n");
  CsvReader wide(folder / "wide.csv", "to test it", bounded);
  CHECK(wide.next(cells));
  CHECK_THROWS_WITH_AS(wide.next(cells), "the file:2: a row of more than 3 cells", OutputError);
  write_file_atomically(folder / "quoted.csv", "a,\"bb\"\"cc\",d\n");
  CsvReader quoted(folder / "quoted.csv", "to test it", bounded);
  CHECK_THROWS_WITH_AS(quoted.next(cells), "the file:1: cell 2, longer than 4 bytes", OutputError);
  write_file_atomically(folder / "endless.csv", std::string(std::size_t{3} << 20, '7'));
  CsvReader endless(folder / "endless.csv", "to test it", bounded);
  CHECK_THROWS_WITH_AS(endless.next(cells), "the file:1: cell 1, longer than 4 bytes", OutputError);
  CHECK(endless.text().size() <= (std::size_t{1} << 20));  // at most a buffer's worth was taken
}

}  // namespace test_host_outputs
