// results.h5's building blocks in-process (builds with HDF5 only): the CSV-table copy (types per column, quoted cells,
// errors naming the line), the sample layout and its slabs (NaN where nothing was written; a slab outside the layout
// refused), HDF5 failures as OutputError naming the file, and /output/format in the job reader.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/observers/hdf5_sample_writer.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/hdf5_file.hpp"
#include "nonsep/host/output/hdf5_samples.hpp"
#include "nonsep/host/output/hdf5_tables.hpp"
#include "nonsep/host/platform/build_features.hpp"

using namespace nonsep::host;
using nonsep::host_testing::TemporaryFolder;
using nonsep::host_testing::write_text;

namespace {

H5T_class_t type_class(const Hdf5File& file, const std::string& path) {
  const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose, "open " + path);
  const Hdf5Handle type = file.own(H5Dget_type(dataset.get()), H5Tclose, "type of " + path);
  return H5Tget_class(type.get());
}

template <class T>
std::vector<T> read_all(const Hdf5File& file, const std::string& path, hid_t memory_type, std::size_t count) {
  std::vector<T> values(count);
  const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose, "open " + path);
  file.check(H5Dread(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), "read " + path);
  return values;
}

std::vector<std::string> read_strings(const Hdf5File& file, const std::string& path, std::size_t count) {
  const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose, "open " + path);
  const Hdf5Handle type = file.own(H5Dget_type(dataset.get()), H5Tclose, "type of " + path);
  std::vector<char*> cells(count);
  file.check(H5Dread(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, cells.data()), "read " + path);
  std::vector<std::string> values(cells.begin(), cells.end());
  const Hdf5Handle space = file.own(H5Dget_space(dataset.get()), H5Sclose, "space of " + path);
  H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, cells.data());
  return values;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("write_csv_table: int64 trajectory and step, float64 numbers (empty = NaN), UTF-8 text, quoted cells") {
  TemporaryFolder folder;
  write_text(folder / "table.csv",
             "trajectory,step,t,note,blank,stop_step\n"
             "0,10,0.5,plain,,3\n"
             "1,20,-1e-300,\"a, \"\"quoted\"\"\nline\",,\n"
             "2,30,nan,é,,inf\n"
             "3,40,1");  // cut off by a hard kill: not a row
  Hdf5File file = Hdf5File::create(folder / "out.h5");
  write_csv_table(file, "table", folder / "table.csv");
  write_csv_table(file, "/table", folder / "table.csv");  // a second copy replaces the group
  CHECK(type_class(file, "/table/trajectory") == H5T_INTEGER);
  CHECK(type_class(file, "/table/step") == H5T_INTEGER);
  CHECK(type_class(file, "/table/t") == H5T_FLOAT);
  CHECK(type_class(file, "/table/blank") == H5T_FLOAT);
  CHECK(type_class(file, "/table/note") == H5T_STRING);
  CHECK(read_all<std::int64_t>(file, "/table/step", H5T_NATIVE_INT64, 3) == std::vector<std::int64_t>{10, 20, 30});
  const auto t = read_all<double>(file, "/table/t", H5T_NATIVE_DOUBLE, 3);
  CHECK(t[0] == 0.5);
  CHECK(t[1] == -1e-300);
  CHECK(std::isnan(t[2]));
  const auto stop = read_all<double>(file, "/table/stop_step", H5T_NATIVE_DOUBLE, 3);
  CHECK(stop[0] == 3.0);
  CHECK(std::isnan(stop[1]));
  CHECK(std::isinf(stop[2]));
  CHECK(read_strings(file, "/table/note", 3) == std::vector<std::string>{"plain", "a, \"quoted\"\nline", "é"});
}

TEST_CASE("write_csv_table: a table without rows gets empty columns, and bad files are OutputErrors naming the line") {
  TemporaryFolder folder;
  Hdf5File file = Hdf5File::create(folder / "out.h5");
  write_text(folder / "empty.csv", "trajectory,t,message\n");
  write_csv_table(file, "empty", folder / "empty.csv");
  CHECK(type_class(file, "/empty/t") == H5T_FLOAT);

  write_text(folder / "ragged.csv", "a,b\n1,2\n3\n");
  CHECK_THROWS_WITH_AS(write_csv_table(file, "ragged", folder / "ragged.csv"),
                       doctest::Contains("ragged.csv:3: found 1 cells; expected 2"), OutputError);
  write_text(folder / "open_quote.csv", "a\n\"never closed\n");
  CHECK_THROWS_WITH_AS(write_csv_table(file, "open", folder / "open_quote.csv"),
                       doctest::Contains("open_quote.csv:2: a quoted cell is not closed"), OutputError);
  CHECK_THROWS_WITH_AS(write_csv_table(file, "missing", folder / "missing.csv"), doctest::Contains("missing.csv"),
                       OutputError);
}

TEST_CASE("SampleDatasets: NaN until written, slabs at any sample and trajectory offset, reopened with its layout") {
  TemporaryFolder folder;
  const SampleLayout layout{3, 4, 2};
  const std::vector<std::uint64_t> steps{0, 5, 7};
  const std::vector<double> times{0.0, 0.5, 0.7};
  {
    Hdf5File file = Hdf5File::create(folder / "results.h5");
    SampleDatasets samples = SampleDatasets::create(file, layout, steps, times);
    // What a rank holding trajectories 1 and 2 writes: samples 1..2 of them.
    const std::vector<double> q{1, 2, 3, 4, 5, 6, 7, 8}, p{-1, -2, -3, -4, -5, -6, -7, -8}, H{10, 20, 30, 40};
    samples.write({.first_sample = 1, .samples = 2, .first_trajectory = 1, .trajectories = 2, .q = q, .p = p, .H = H});
    CHECK_THROWS_WITH_AS(
        samples.write(
            {.first_sample = 2, .samples = 2, .first_trajectory = 0, .trajectories = 1, .q = q, .p = p, .H = H}),
        doctest::Contains("results.h5: cannot write samples 2 + 2"), OutputError);
    file.close();
  }
  Hdf5File file = Hdf5File::open(folder / "results.h5");
  const SampleDatasets samples = SampleDatasets::open(file);
  CHECK(samples.layout() == layout);
  CHECK(read_all<std::uint64_t>(file, "/samples/step", H5T_NATIVE_UINT64, 3) == steps);
  const auto q = read_all<double>(file, "/samples/q", H5T_NATIVE_DOUBLE, 24);
  const auto H = read_all<double>(file, "/samples/H", H5T_NATIVE_DOUBLE, 12);
  CHECK(q[(1 * 4 + 1) * 2 + 0] == 1.0);  // sample 1, trajectory 1, q0
  CHECK(q[(2 * 4 + 2) * 2 + 1] == 8.0);  // sample 2, trajectory 2, q1
  CHECK(H[1 * 4 + 2] == 20.0);
  int written = 0;
  for (double x : q) written += !std::isnan(x);
  CHECK(written == 8);
  CHECK(std::isnan(H[0]));
  CHECK(std::isnan(H[1 * 4 + 3]));
}

TEST_CASE("HDF5 failures are OutputErrors naming the file and what failed") {
  TemporaryFolder folder;
  write_text(folder / "not.h5", "text, not HDF5\n");
  const std::string expected = (folder / "not.h5").string() + ": cannot open the HDF5 file for writing (HDF5:";
  CHECK_THROWS_WITH_AS(Hdf5File::open(folder / "not.h5"), doctest::Contains(expected.c_str()), OutputError);
  CHECK_THROWS_WITH_AS(Hdf5File::create(folder / "no such folder" / "results.h5"),
                       doctest::Contains("results.h5: cannot create the HDF5 file"), OutputError);
  Hdf5File file = Hdf5File::create(folder / "results.h5");
  CHECK_THROWS_WITH_AS(SampleDatasets::open(file), doctest::Contains("cannot find /samples/q"), OutputError);
}

TEST_CASE("the sample steps: 0, every multiple of every, and the last step once") {
  CHECK(Hdf5SampleWriter::sample_steps(10, 3) == std::vector<std::uint64_t>{0, 3, 6, 9, 10});
  CHECK(Hdf5SampleWriter::sample_steps(9, 3) == std::vector<std::uint64_t>{0, 3, 6, 9});
  CHECK(Hdf5SampleWriter::sample_steps(5, 10) == std::vector<std::uint64_t>{0, 5});
  CHECK(Hdf5SampleWriter::sample_steps(1, 1) == std::vector<std::uint64_t>{0, 1});
}

TEST_CASE("/output/format: csv by default, hdf5 in a build with HDF5, anything else an issue at /output/format") {
  const auto parse = [](const nlohmann::json& output) {
    nlohmann::json document = nonsep::host_testing::quickstart_job();
    document["output"] = output;
    std::vector<JobIssue> issues;
    Job job = parse_job(document, "/jobs/test.json", issues);
    return std::make_pair(std::move(job), std::move(issues));
  };
  CHECK(parse(nlohmann::json::object()).first.run().format == OutputFormat::csv);
  auto [job, issues] = parse({{"format", "hdf5"}});
  REQUIRE(built_with_hdf5());  // this file is compiled only then
  CHECK(issues.empty());
  CHECK(job.run().format == OutputFormat::hdf5);
  for (const nlohmann::json& bad : {nlohmann::json("HDF5"), nlohmann::json(5), nlohmann::json(nullptr)}) {
    const auto refused = parse({{"format", bad}}).second;
    REQUIRE(refused.size() == 1);
    CHECK(refused[0].path == "/output/format");
    CHECK(contains(refused[0].allowed, "\"csv\" or \"hdf5\""));
  }
}

TEST_CASE(
    "Hdf5SampleWriter: a trajectory that stops exactly at a sample step has its final state there as in "
    "trajectory.csv, one that stopped before has NaN, and a resumed writer rewrites the rows after its checkpoint") {
  TemporaryFolder folder;
  const TimeGrid time = TimeGrid::of_steps(10, 0.5);
  const auto path = folder / "results.h5";
  const auto state = [](std::size_t trajectory, double x) {
    static std::vector<double> storage(64);
    storage[2 * trajectory] = x;
    return StateView{.trajectory = trajectory,
                     .q = std::span(storage).subspan(2 * trajectory, 1),
                     .p = std::span(storage).subspan(2 * trajectory + 1, 1),
                     .energy = x * 10};
  };
  TrajectoryRecord at_sample, between;
  at_sample.final_step = 4;
  at_sample.final_q = {7.0};
  at_sample.final_p = {-7.0};
  at_sample.energy_final = 70.0;
  between.final_step = 3;
  between.final_q = {9.0};
  between.final_p = {-9.0};
  nlohmann::json checkpoint;
  {
    Hdf5SampleWriter writer(path, 1, 3, 4, time, false);  // samples at steps 0, 4, 8, 10
    std::vector<StateView> all{state(0, 1.0), state(1, 2.0), state(2, 3.0)};
    writer.on_event({.step = 0, .t = 0.0, .states = all, .energy_evaluated = true});
    checkpoint = writer.save();
    CHECK(checkpoint == nlohmann::json{{"rows", 1}});
    writer.on_retire(2, between);    // stopped at step 3: no sample
    writer.on_retire(1, at_sample);  // stopped at step 4, before the event there
    std::vector<StateView> left{state(0, 4.0)};
    writer.on_event({.step = 4, .t = 2.0, .states = left, .energy_evaluated = true});
    writer.on_event({.step = 8, .t = 4.0, .states = left, .energy_evaluated = false});
    writer.on_end();
  }
  Hdf5File file = Hdf5File::open(path);
  const auto q = read_all<double>(file, "/samples/q", H5T_NATIVE_DOUBLE, 12);  // [4 samples][3 trajectories][1]
  const auto H = read_all<double>(file, "/samples/H", H5T_NATIVE_DOUBLE, 12);
  CHECK(read_all<std::uint64_t>(file, "/samples/step", H5T_NATIVE_UINT64, 4) ==
        std::vector<std::uint64_t>{0, 4, 8, 10});
  CHECK(q[0] == 1.0);
  CHECK(q[3 + 0] == 4.0);
  CHECK(q[3 + 1] == 7.0);  // the final state at its sample step
  CHECK(H[3 + 1] == 70.0);
  CHECK(std::isnan(q[3 + 2]));  // stopped before
  CHECK(std::isnan(q[6 + 1]));
  CHECK(H[6 + 0] == 40.0);      // StateView::energy as given (the driver leaves it empty where H was not evaluated)
  CHECK(std::isnan(q[9 + 0]));  // step 10 not reached
  file.close();

  Hdf5SampleWriter resumed(path, 1, 3, 4, time, true);
  resumed.restore(checkpoint);
  std::vector<StateView> other{state(0, 5.0)};
  resumed.on_event({.step = 4, .t = 2.0, .states = other, .energy_evaluated = true});
  resumed.on_end();
  Hdf5File again = Hdf5File::open(path);
  const auto resumed_q = read_all<double>(again, "/samples/q", H5T_NATIVE_DOUBLE, 12);
  CHECK(resumed_q[3] == 5.0);
  CHECK(resumed_q[0] == 1.0);  // the row before the checkpoint, in the same chunk: read back and written again
  CHECK(std::isnan(resumed_q[6 + 1]));
  again.close();
  Hdf5SampleWriter wrong(path, 2, 3, 4, time, true);
  CHECK_THROWS_WITH_AS(wrong.restore(checkpoint), doctest::Contains("cannot resume into"),
                       nonsep::host::CheckpointError);
  CHECK_THROWS_WITH_AS(resumed.restore(nlohmann::json{{"rows", 5}}), doctest::Contains("results_h5 state is damaged"),
                       nonsep::host::CheckpointError);
}
