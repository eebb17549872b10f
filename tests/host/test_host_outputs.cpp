// The output writers in-process: trajectory.csv's layout and number format, summary.json's text and its atomic
// replacement.
#include <doctest/doctest.h>

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
#include "nonsep/host/output_files.hpp"
#include "nonsep/host/summary_json.hpp"

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

// summary.json's /trajectories is written as text (summary_json.hpp). These check it against nlohmann's own dump
// of the same document built as json values (how the runner built it before), number by number and, where
// nlohmann's number text is also the shortest, character by character.

TEST_CASE("summary.json numbers: shortest round-trip text in nlohmann's layout, null when not finite") {
  const auto text = [](double x) {
    std::string out;
    append_json_number(out, x);
    return out;
  };
  CHECK(text(0.0) == "0.0");
  CHECK(text(-0.0) == "-0.0");
  CHECK(text(2.0) == "2.0");
  CHECK(text(-1.5) == "-1.5");
  CHECK(text(123456789012345.0) == "123456789012345.0");
  CHECK(text(1e14) == "100000000000000.0");
  CHECK(text(1e15) == "1e+15");
  CHECK(text(1e-4) == "0.0001");
  CHECK(text(1e-5) == "1e-05");
  CHECK(text(-2.5e-300) == "-2.5e-300");
  CHECK(text(5e-324) == "5e-324");
  CHECK(text(0.3863765573361232) == "0.3863765573361232");
  CHECK(text(std::numeric_limits<double>::infinity()) == "null");
  CHECK(text(-std::numeric_limits<double>::infinity()) == "null");
  CHECK(text(std::numeric_limits<double>::quiet_NaN()) == "null");
  // Against nlohmann on random bit patterns and on numbers of every scale: the same double back, bit for bit;
  // never longer; the same text except where nlohmann's Grisu2 digits are not the shortest (a few in a thousand).
  std::mt19937_64 random(20261123);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::size_t checked = 0, same_text = 0;
  for (int i = 0; i < 60000; ++i) {
    const std::uint64_t bits = random();
    double x = 0.0;
    std::memcpy(&x, &bits, sizeof x);
    for (const double value : {x, uniform(random), std::pow(10.0, 30.0 * uniform(random)) * uniform(random),
                               std::round(uniform(random) * 1e6) / 1e3}) {
      if (!std::isfinite(value)) continue;
      const std::string ours = text(value), theirs = nlohmann::ordered_json(value).dump();
      const double back = nlohmann::json::parse(ours).get<double>();
      REQUIRE(std::memcmp(&back, &value, sizeof back) == 0);
      REQUIRE(ours.size() <= theirs.size());
      REQUIRE(nlohmann::json::parse(ours).is_number_float());
      ++checked;
      if (ours == theirs) ++same_text;
    }
  }
  CHECK(checked > 200000);
  CHECK(same_text > checked * 99 / 100);
}

namespace {

using ordered_json = nlohmann::ordered_json;

ordered_json or_null(std::optional<double> value) {
  return value && std::isfinite(*value) ? ordered_json(*value) : ordered_json(nullptr);
}

// The entry as json values, the way the runner built it before the text writer.
ordered_json reference_entry(std::size_t index, const TrajectoryRecord& record, std::vector<double> q0,
                             std::vector<double> p0, bool closest_return) {
  ordered_json entry;
  entry["index"] = index;
  entry["status"] = record.status;
  entry["initial"] = {{"q", q0}, {"p", p0}};
  entry["final"] = {{"t", record.final_t}, {"step", record.final_step}, {"q", record.final_q}, {"p", record.final_p}};
  const bool relative_known = record.energy_initial && *record.energy_initial != 0.0;
  std::optional<double> relative_final;
  if (relative_known && record.energy_final)
    relative_final = (*record.energy_final - *record.energy_initial) / *record.energy_initial;
  entry["energy"] = {{"initial", or_null(record.energy_initial)},
                     {"final", or_null(record.energy_final)},
                     {"relative_error_final", or_null(relative_final)},
                     {"relative_error_max_abs", relative_known ? or_null(record.max_abs_relative_error) : nullptr}};
  if (record.status == "diverged")
    entry["diverged"] = {
        {"step", record.diverged_step}, {"t", record.diverged_t}, {"variable", record.diverged_variable}};
  if (!record.error.empty()) entry["error"] = record.error;
  if (closest_return)
    entry["closest_return"] = record.closest_distance ? ordered_json{{"distance", *record.closest_distance},
                                                                     {"t", record.closest_t},
                                                                     {"step", record.closest_step}}
                                                      : ordered_json(nullptr);
  return entry;
}

}  // namespace

TEST_CASE("summary.json: the trajectory entries written as text are nlohmann's dump(2) of the same values") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const std::size_t dimension : {std::size_t{1}, std::size_t{3}}) {
    std::vector<TrajectoryRecord> records(5);
    std::vector<double> q0, p0;
    for (std::size_t i = 0; i < records.size() * dimension; ++i) {
      q0.push_back(0.25 * static_cast<double>(i) - 1.0);
      p0.push_back(i % 2 == 0 ? 0.0 : 1e-7 * static_cast<double>(i));
    }
    for (std::size_t t = 0; t < records.size(); ++t) {
      TrajectoryRecord& r = records[t];
      r.status = "completed";
      r.final_step = 78 + t;
      r.final_t = 0.005 * static_cast<double>(r.final_step);
      for (std::size_t i = 0; i < dimension; ++i) {
        r.final_q.push_back(0.0021775750506204394 * static_cast<double>(i + 1));
        r.final_p.push_back(-1.546307125954331 + static_cast<double>(i));
      }
      r.energy_initial = 5.0;
      r.energy_final = 4.8205;
      r.max_abs_relative_error = 0.0359;
    }
    records[1].status = "diverged";  // its last finite state; the first non-finite variable
    records[1].diverged_step = 12;
    records[1].diverged_t = 0.06;
    records[1].diverged_variable = "p[0]";
    records[1].energy_final.reset();
    records[2].status = "failed";  // a plugin's message: quotes, a backslash, a control character, invalid UTF-8
    records[2].error = "plugin 'x' failed: \"p\" \\ out of range\n\t\xff\xfe (x \xc3\xa9)";
    records[2].final_q[0] = nan;
    records[2].final_p[0] = inf;
    records[3].energy_initial = 0.0;  // relative errors unknown: null
    records[3].closest_distance = 1.25e-3;
    records[3].closest_t = 12.5;
    records[3].closest_step = 2500;
    records[4].energy_initial.reset();
    records[4].energy_final.reset();
    for (const bool closest_return : {false, true}) {
      CAPTURE(dimension);
      CAPTURE(closest_return);
      ordered_json header = {{"status", "failed"},
                             {"model",
                              {{"parameters",
                                {{"trajectories", "null"}, {"label", "\n  \"trajectories\": null"}}}}},
                             {"trajectories", nullptr},
                             {"counts", {{"completed", 3}, {"diverged", 1}}},
                             {"wall_seconds", 0.125}};
      const TrajectoryEntries entries{records, q0, p0, dimension, closest_return};
      const std::string text = summary_json_text(header, entries);
      ordered_json reference = header;
      reference["trajectories"] = ordered_json::array();
      for (std::size_t t = 0; t < records.size(); ++t)
        reference["trajectories"].push_back(reference_entry(
            t, records[t], std::vector<double>(q0.begin() + static_cast<std::ptrdiff_t>(t * dimension),
                                               q0.begin() + static_cast<std::ptrdiff_t>((t + 1) * dimension)),
            std::vector<double>(p0.begin() + static_cast<std::ptrdiff_t>(t * dimension),
                                p0.begin() + static_cast<std::ptrdiff_t>((t + 1) * dimension)),
            closest_return));
      CHECK(text == reference.dump(2, ' ', false, ordered_json::error_handler_t::replace) + "\n");
      const ordered_json parsed = ordered_json::parse(text);
      CHECK(parsed["trajectories"].size() == records.size());
      CHECK(parsed["trajectories"][2]["error"].get<std::string>().find("\xef\xbf\xbd") != std::string::npos);
      CHECK(parsed["trajectories"][2]["final"]["q"][0].is_null());
      CHECK(parsed["trajectories"][3]["energy"]["relative_error_final"].is_null());
      CHECK(parsed["trajectories"][1]["diverged"]["variable"] == "p[0]");
      CHECK(parsed["model"]["parameters"]["label"] == "\n  \"trajectories\": null");
    }
  }
  // No trajectories: an empty array, as nlohmann writes it.
  const ordered_json header = {{"status", "completed"}, {"trajectories", nullptr}};
  CHECK(summary_json_text(header, TrajectoryEntries{}) ==
        "{\n  \"status\": \"completed\",\n  \"trajectories\": []\n}\n");
  CHECK_THROWS_AS(summary_json_text(ordered_json{{"status", "completed"}}, TrajectoryEntries{}), std::logic_error);
}

TEST_CASE("summary.json: a large ensemble's entries are the same text on any number of threads") {
  std::vector<TrajectoryRecord> records(2000);
  std::vector<double> q0(records.size()), p0(records.size());
  for (std::size_t t = 0; t < records.size(); ++t) {
    q0[t] = 0.001 * static_cast<double>(t);
    p0[t] = -q0[t];
    records[t].status = t % 7 == 0 ? "diverged" : "completed";
    records[t].final_step = t;
    records[t].final_q = {std::sqrt(static_cast<double>(t))};
    records[t].final_p = {1.0 / (1.0 + static_cast<double>(t))};
  }
  const nlohmann::ordered_json header = {{"trajectories", nullptr}};
  const TrajectoryEntries entries{records, q0, p0, 1, false};
  const std::string one = summary_json_text(header, entries, 1);
  for (const unsigned threads : {2u, 3u, 16u}) CHECK(summary_json_text(header, entries, threads) == one);
  const auto parsed = nlohmann::ordered_json::parse(one);
  REQUIRE(parsed["trajectories"].size() == records.size());
  for (std::size_t t = 0; t < records.size(); t += 111) {
    CHECK(parsed["trajectories"][t]["index"] == t);
    CHECK(parsed["trajectories"][t]["final"]["q"][0].get<double>() == records[t].final_q[0]);
  }
}

TEST_CASE("summary.json is streamed to its file atomically; an unfinished AtomicFile leaves the old file") {
  TemporaryFolder folder;
  std::vector<TrajectoryRecord> records(700);
  std::vector<double> q0(2 * records.size(), 0.5), p0(2 * records.size(), -0.25);
  for (std::size_t t = 0; t < records.size(); ++t) {
    records[t].status = "completed";
    records[t].final_q = {0.1 * static_cast<double>(t), 1.0};
    records[t].final_p = {-1.0, 1e-9 * static_cast<double>(t)};
  }
  const nlohmann::ordered_json header = {{"status", "completed"}, {"trajectories", nullptr}, {"wall_seconds", 1.5}};
  const TrajectoryEntries entries{records, q0, p0, 2, false};
  const auto path = folder / "summary.json";
  for (const unsigned threads : {1u, 2u}) {
    write_summary_json(path, header, entries, threads);
    CHECK(read_text(path) == summary_json_text(header, entries));
  }
  {
    AtomicFile unfinished(path);
    unfinished.write("{\"status\": \"half");
  }  // destroyed without commit()
  CHECK(read_text(path) == summary_json_text(header, entries));
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder.path())) {
    (void)entry;
    ++files;
  }
  CHECK(files == 1);
  CHECK_THROWS_WITH_AS(write_summary_json(folder / "missing" / "summary.json", header, entries),
                       doctest::Contains("missing/.summary.json.tmp-"), OutputError);
}
