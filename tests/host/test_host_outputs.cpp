// The output writers in-process: trajectory.csv's layout and number format, and summary.json's atomic replacement.
#include <doctest/doctest.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "host_test_support.hpp"
#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output_files.hpp"

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

TEST_CASE("trajectory.csv: header, one row per sample, empty energy cells when unknown") {
  TemporaryFolder folder;
  const auto path = folder / "trajectory.csv";
  {
    TrajectoryWriter writer(path, 2);
    const double q[] = {1.0, 0.1}, p[] = {-0.5, 2.0};
    writer.write(0, 0, 0.0, q, p, 5.0, 0.0);
    writer.write(3, 17, 0.125, q, p, std::nullopt, std::nullopt);
    writer.flush();
  }
  const auto rows = read_csv(path);
  REQUIRE(rows.size() == 3);
  CHECK(rows[0] == std::vector<std::string>{"trajectory", "step", "t", "q0", "q1", "p0", "p1", "H",
                                            "relative_energy_error"});
  CHECK(rows[1] == std::vector<std::string>{"0", "0", "0", "1", "0.1", "-0.5", "2", "5", "0"});
  CHECK(rows[2] == std::vector<std::string>{"3", "17", "0.125", "1", "0.1", "-0.5", "2", "", ""});
}

TEST_CASE("trajectory.csv: rows reach the file when the buffer fills and when the writer is destroyed") {
  TemporaryFolder folder;
  const auto path = folder / "trajectory.csv";
  const double q[] = {1.0}, p[] = {2.0};
  std::size_t rows_written = 0;
  {
    TrajectoryWriter writer(path, 1);
    while (read_text(path).empty()) {
      writer.write(0, rows_written, 0.5, q, p, 1.0, 0.0);
      ++rows_written;
      REQUIRE(rows_written < 100000);
    }
    CHECK(rows_written > 100);  // buffered, not one write per row
  }
  CHECK(read_csv(path).size() == rows_written + 1);
}

TEST_CASE("a trajectory.csv that cannot be created is an OutputError naming the file") {
  TemporaryFolder folder;
  CHECK_THROWS_WITH_AS(TrajectoryWriter(folder / "missing" / "trajectory.csv", 1),
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
