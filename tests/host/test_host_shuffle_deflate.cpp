// /samples' chunks filtered by our code (output/shuffle_deflate.hpp): the bytes inflate (plain zlib) and unshuffle
// to the chunk again, for random mantissas, constants and NaN; the planes that compress are deflated and the
// random mantissa planes stored; and HDF5 itself reads the chunks that SampleDatasets writes directly with the
// dataset's declared shuffle and deflate filters, equal to those it filtered itself (builds with HDF5 only).
#include <doctest/doctest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <span>
#include <vector>

#include "host_test_support.hpp"
#include "nonsep/host/output/hdf5_file.hpp"
#include "nonsep/host/output/hdf5_samples.hpp"
#include "nonsep/host/output/shuffle_deflate.hpp"

using namespace nonsep::host;
using nonsep::host_testing::TemporaryFolder;

namespace {

std::span<const unsigned char> bytes_of(const std::vector<double>& values) {
  return {reinterpret_cast<const unsigned char*>(values.data()), values.size() * sizeof(double)};
}

// zlib's inflate and HDF5's unshuffle (byte k of element i is at k * count + i), written independently here.
std::vector<double> inflate_and_unshuffle(std::span<const unsigned char> filtered, std::size_t count) {
  std::vector<unsigned char> shuffled(count * sizeof(double));
  uLongf size = shuffled.size();
  REQUIRE(uncompress(shuffled.data(), &size, filtered.data(), filtered.size()) == Z_OK);
  REQUIRE(size == shuffled.size());
  std::vector<double> values(count);
  auto* out = reinterpret_cast<unsigned char*>(values.data());
  for (std::size_t i = 0; i < count; ++i)
    for (std::size_t k = 0; k < sizeof(double); ++k) out[i * sizeof(double) + k] = shuffled[k * count + i];
  return values;
}

std::vector<double> uniform(std::size_t count, double from, double to, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> draw(from, to);
  std::vector<double> values(count);
  for (double& x : values) x = draw(random);
  return values;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("ShuffleDeflate: the zlib stream of the shuffled planes, random mantissa planes stored, the rest deflated") {
  ShuffleDeflate filter(1);
  const std::size_t count = 65536;
  const double nan = std::numeric_limits<double>::quiet_NaN();

  // In [1, 2): sign and exponent fixed (planes 7 and the top of 6), the 52 mantissa bits random (planes 0 to 5).
  const std::vector<double> random = uniform(count, 1.0, 2.0, 7);
  const auto filtered = filter.filter(bytes_of(random), sizeof(double));
  const std::vector<unsigned char> first(filtered.begin(), filtered.end());
  CHECK(filter.deflated_planes() == 2);
  // 6 stored planes; plane 6 has 16 values (4 bits), plane 7 one.
  CHECK(first.size() < random.size() * sizeof(double) * 6.6 / 8.0);
  CHECK(same_bits(inflate_and_unshuffle(first, count), random));

  std::vector<double> constant(count, 0.5);
  const auto small = filter.filter(bytes_of(constant), sizeof(double));
  CHECK(filter.deflated_planes() == 8);
  CHECK(small.size() < 5000);  // deflate's longest match is 258 bytes
  CHECK(same_bits(inflate_and_unshuffle(small, count), constant));

  // The padding of an edge chunk: real numbers first, NaN after. The trial pieces see the NaN.
  std::vector<double> edge(count, nan);
  std::copy(random.begin(), random.begin() + 1552, edge.begin());
  const auto padded = filter.filter(bytes_of(edge), sizeof(double));
  CHECK(filter.deflated_planes() == 8);
  CHECK(padded.size() < 1552 * sizeof(double) + 4000);
  CHECK(same_bits(inflate_and_unshuffle(padded, count), edge));

  // The same chunk gives the same bytes, whatever was filtered before.
  const auto again = filter.filter(bytes_of(random), sizeof(double));
  CHECK(std::vector<unsigned char>(again.begin(), again.end()) == first);

  // Chunks smaller than a trial, and a single element (shuffle is then the identity).
  const std::vector<double> few{1.0, -2.5, nan};
  CHECK(same_bits(inflate_and_unshuffle(filter.filter(bytes_of(few), sizeof(double)), few.size()), few));
  const std::vector<double> one{3.25};
  CHECK(same_bits(inflate_and_unshuffle(filter.filter(bytes_of(one), sizeof(double)), 1), one));
}

TEST_CASE("SampleDatasets: whole chunks are written directly and read by HDF5 as the chunks it filters itself") {
  TemporaryFolder folder;
  // 70000 trajectories of dimension 1: chunks of one sample and 65536 trajectories, the second chunk an edge chunk.
  const SampleLayout layout{2, 70000, 1};
  const std::vector<std::uint64_t> steps{0, 1};
  const std::vector<double> times{0.0, 0.1};
  const std::vector<double> q = uniform(2 * 70000, -1.0, 1.0, 1), p = uniform(2 * 70000, -3.0, 3.0, 2);
  std::vector<double> H = uniform(2 * 70000, 0.0, 1.0, 3);
  std::fill(H.begin() + 1000, H.begin() + 9000, std::numeric_limits<double>::quiet_NaN());
  const auto write = [&](const std::filesystem::path& path, bool whole) {
    Hdf5File file = Hdf5File::create(path);
    SampleDatasets samples = SampleDatasets::create(file, layout, steps, times);
    CHECK(samples.samples_per_chunk() == 1);
    if (whole) {
      samples.write(
          {.first_sample = 0, .samples = 2, .first_trajectory = 0, .trajectories = 70000, .q = q, .p = p, .H = H});
    } else {  // slabs that are not whole chunks go through HDF5's filter pipeline
      for (std::uint64_t s = 0; s < 2; ++s)
        for (const auto& [first, size] : {std::pair<std::uint64_t, std::uint64_t>{0, 40000}, {40000, 30000}}) {
          std::vector<double> qs, ps, Hs;
          for (std::uint64_t j = first; j < first + size; ++j) {
            qs.push_back(q[s * 70000 + j]);
            ps.push_back(p[s * 70000 + j]);
            Hs.push_back(H[s * 70000 + j]);
          }
          samples.write({.first_sample = s,
                         .samples = 1,
                         .first_trajectory = first,
                         .trajectories = size,
                         .q = qs,
                         .p = ps,
                         .H = Hs});
        }
    }
    file.close();
  };
  write(folder / "direct.h5", true);
  write(folder / "library.h5", false);

  const auto read = [](const Hdf5File& file, const char* path, std::size_t count) {
    std::vector<double> values(count);
    const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path, H5P_DEFAULT), H5Dclose, path);
    file.check(H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), path);
    return values;
  };
  const auto raw_chunk = [](const Hdf5File& file, const char* path, hsize_t trajectory) {
    const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path, H5P_DEFAULT), H5Dclose, path);
    const std::array<hsize_t, 3> offset{1, trajectory, 0};
    hsize_t size = 0;
    file.check(H5Dget_chunk_storage_size(dataset.get(), offset.data(), &size), path);
    std::vector<unsigned char> bytes(size);
    std::uint32_t mask = 0;
    file.check(H5Dread_chunk(dataset.get(), H5P_DEFAULT, offset.data(), &mask, bytes.data()), path);
    CHECK(mask == 0);  // every declared filter applied
    return bytes;
  };
  const Hdf5File direct = Hdf5File::open(folder / "direct.h5"), library = Hdf5File::open(folder / "library.h5");
  for (const auto& [path, values] : {std::pair{"/samples/q", &q}, std::pair{"/samples/p", &p},
                                     std::pair{"/samples/H", static_cast<const std::vector<double>*>(&H)}}) {
    CHECK(same_bits(read(direct, path, values->size()), *values));
    CHECK(same_bits(read(library, path, values->size()), *values));
  }
  // The stored chunks are ShuffleDeflate's (the direct path was taken); the edge chunk is padded with NaN, HDF5's
  // fill value. A chunk of random numbers differs from the library's deflate at level 1 of all planes; the edge
  // chunk, mostly NaN, has all its planes deflated, and then the bytes are the library's.
  ShuffleDeflate filter(hdf5_deflate_level);
  const std::vector<double> full(q.begin() + 70000, q.begin() + 70000 + 65536);
  const auto filtered = filter.filter(bytes_of(full), sizeof(double));
  const std::vector<unsigned char> expected(filtered.begin(), filtered.end());
  CHECK(raw_chunk(direct, "/samples/q", 0) == expected);
  CHECK(raw_chunk(library, "/samples/q", 0) != expected);
  std::vector<double> edge(65536, std::numeric_limits<double>::quiet_NaN());
  std::copy(q.begin() + 70000 + 65536, q.end(), edge.begin());
  const auto padded = filter.filter(bytes_of(edge), sizeof(double));
  CHECK(filter.deflated_planes() == 8);
  CHECK(raw_chunk(direct, "/samples/q", 65536) == std::vector<unsigned char>(padded.begin(), padded.end()));
  CHECK(raw_chunk(library, "/samples/q", 65536) == std::vector<unsigned char>(padded.begin(), padded.end()));
}
