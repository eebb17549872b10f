#include "nonsep/host/output/hdf5_samples.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <vector>

namespace nonsep::host {

namespace {

constexpr hsize_t chunk_numbers = 65536;

// One dataset of /samples: `dims` numbers of `type`, chunked as `chunk`, shuffled and deflated; NaN unless written
// (for float64 datasets).
Hdf5Handle create_dataset(const Hdf5File& file, hid_t group, const char* name, hid_t type,
                          std::span<const hsize_t> dims, std::span<const hsize_t> chunk) {
  const std::string what = std::string("create ") + samples_group + "/" + name;
  const Hdf5Handle space =
      file.own(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, what);
  const Hdf5Handle properties = untimed_dataset_properties(file);
  file.check(H5Pset_chunk(properties.get(), static_cast<int>(chunk.size()), chunk.data()), what);
  file.check(H5Pset_shuffle(properties.get()), what);
  file.check(H5Pset_deflate(properties.get(), hdf5_deflate_level), what);
  if (H5Tequal(type, H5T_NATIVE_DOUBLE) > 0) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    file.check(H5Pset_fill_value(properties.get(), H5T_NATIVE_DOUBLE, &nan), what);
  }
  // A chunk cache that holds a few whole chunks, so that rows written one at a time into a chunk spanning several
  // samples are compressed once, when the chunk is complete, not once a row.
  const Hdf5Handle access = file.own(H5Pcreate(H5P_DATASET_ACCESS), H5Pclose, what);
  file.check(H5Pset_chunk_cache(access.get(), 521, 4u << 20, 1.0), what);
  const hid_t stored = H5Tequal(type, H5T_NATIVE_DOUBLE) > 0 ? H5T_IEEE_F64LE : H5T_STD_U64LE;
  return file.own(H5Dcreate2(group, name, stored, space.get(), H5P_DEFAULT, properties.get(), access.get()), H5Dclose,
                  what);
}

Hdf5Handle open_dataset(const Hdf5File& file, const char* name, std::vector<hsize_t>& dims) {
  const std::string path = std::string(samples_group) + "/" + name;
  if (H5Lexists(file.id(), samples_group, H5P_DEFAULT) <= 0 || H5Lexists(file.id(), path.c_str(), H5P_DEFAULT) <= 0)
    file.fail("find " + path + " (the file was not written by this run's output.format \"hdf5\")");
  Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose, "open " + path);
  const Hdf5Handle space = file.own(H5Dget_space(dataset.get()), H5Sclose, "read the shape of " + path);
  const int rank = file.check(H5Sget_simple_extent_ndims(space.get()), "read the shape of " + path);
  dims.assign(static_cast<std::size_t>(rank), 0);
  file.check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), "read the shape of " + path);
  return dataset;
}

// An empty `values` selects nothing: a rank's share of a collective write that has no slab this round.
void write_block(const Hdf5File& file, hid_t dataset, const char* name, std::span<const hsize_t> start,
                 std::span<const hsize_t> count, std::span<const double> values, hid_t transfer) {
  const std::string what = std::string("write samples to ") + samples_group + "/" + name;
  const Hdf5Handle space = file.own(H5Dget_space(dataset), H5Sclose, what);
  const hsize_t size = std::max<hsize_t>(1, values.size());
  const Hdf5Handle memory = file.own(H5Screate_simple(1, &size, nullptr), H5Sclose, what);
  if (values.empty()) {
    file.check(H5Sselect_none(space.get()), what);
    file.check(H5Sselect_none(memory.get()), what);
  } else {
    file.check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), what);
  }
  const double nothing = 0.0;
  file.check(H5Dwrite(dataset, H5T_NATIVE_DOUBLE, memory.get(), space.get(), transfer,
                      values.empty() ? &nothing : values.data()),
             what);
}

}  // namespace

SampleDatasets SampleDatasets::create(const Hdf5File& file, const SampleLayout& layout,
                                      std::span<const std::uint64_t> steps, std::span<const double> times,
                                      hid_t transfer) {
  if (steps.size() != layout.samples || times.size() != layout.samples || layout.samples == 0 ||
      layout.trajectories == 0 || layout.dimension == 0)
    file.fail("create " + std::string(samples_group) + " of " + std::to_string(layout.samples) + " samples with " +
              std::to_string(steps.size()) + " steps and " + std::to_string(times.size()) + " times");
  const Hdf5Handle properties = untimed_group_properties(file);
  const Hdf5Handle group = file.own(H5Gcreate2(file.id(), samples_group, H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                                    H5Gclose, std::string("create the group ") + samples_group);
  const hsize_t S = layout.samples, N = layout.trajectories, n = layout.dimension;
  const hsize_t trajectories_per_chunk = std::min(N, std::max<hsize_t>(1, chunk_numbers / n));
  const hsize_t samples_per_chunk = std::min(S, std::max<hsize_t>(1, chunk_numbers / (trajectories_per_chunk * n)));
  const std::array<hsize_t, 1> list{S}, list_chunk{std::min<hsize_t>(S, chunk_numbers)};
  const std::array<hsize_t, 3> state{S, N, n}, state_chunk{samples_per_chunk, trajectories_per_chunk, n};
  const std::array<hsize_t, 2> energy{S, N}, energy_chunk{samples_per_chunk, trajectories_per_chunk};

  const Hdf5Handle step = create_dataset(file, group.get(), "step", H5T_NATIVE_UINT64, list, list_chunk);
  file.check(H5Dwrite(step.get(), H5T_NATIVE_UINT64, H5S_ALL, H5S_ALL, transfer, steps.data()), "write /samples/step");
  const Hdf5Handle t = create_dataset(file, group.get(), "t", H5T_NATIVE_DOUBLE, list, list_chunk);
  file.check(H5Dwrite(t.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, transfer, times.data()), "write /samples/t");
  SampleDatasets datasets(file);
  datasets.layout_ = layout;
  datasets.transfer_ = transfer;
  datasets.q_ = create_dataset(file, group.get(), "q", H5T_NATIVE_DOUBLE, state, state_chunk);
  datasets.p_ = create_dataset(file, group.get(), "p", H5T_NATIVE_DOUBLE, state, state_chunk);
  datasets.H_ = create_dataset(file, group.get(), "H", H5T_NATIVE_DOUBLE, energy, energy_chunk);
  return datasets;
}

SampleDatasets SampleDatasets::open(const Hdf5File& file) {
  SampleDatasets datasets(file);
  std::vector<hsize_t> q, p, H, step;
  datasets.q_ = open_dataset(file, "q", q);
  datasets.p_ = open_dataset(file, "p", p);
  datasets.H_ = open_dataset(file, "H", H);
  open_dataset(file, "step", step);
  if (q.size() != 3 || p != q || H.size() != 2 || H[0] != q[0] || H[1] != q[1] || step.size() != 1 || step[0] != q[0])
    file.fail("use /samples: its datasets q [S, N, n], p [S, N, n], H [S, N] and step [S] do not fit together");
  datasets.layout_ = {q[0], q[1], q[2]};
  return datasets;
}

void SampleDatasets::write(const SampleSlab& slab) {
  const SampleLayout& l = layout_;
  const std::uint64_t cells = slab.samples * slab.trajectories;
  if (slab.first_sample + slab.samples > l.samples || slab.first_trajectory + slab.trajectories > l.trajectories ||
      slab.q.size() != cells * l.dimension || slab.p.size() != cells * l.dimension || slab.H.size() != cells)
    file_->fail("write samples " + std::to_string(slab.first_sample) + " + " + std::to_string(slab.samples) +
                " of trajectories " + std::to_string(slab.first_trajectory) + " + " +
                std::to_string(slab.trajectories) + " with " + std::to_string(slab.q.size()) + " numbers of q into " +
                std::to_string(l.samples) + " samples of " + std::to_string(l.trajectories) + " trajectories");
  if (cells == 0 && transfer_ == H5P_DEFAULT) return;  // in a collective write, an empty share still takes part
  const std::array<hsize_t, 3> start{slab.first_sample, slab.first_trajectory, 0},
      count{slab.samples, slab.trajectories, l.dimension};
  write_block(*file_, q_.get(), "q", start, count, slab.q, transfer_);
  write_block(*file_, p_.get(), "p", start, count, slab.p, transfer_);
  write_block(*file_, H_.get(), "H", std::span(start).first<2>(), std::span(count).first<2>(), slab.H, transfer_);
}

}  // namespace nonsep::host
