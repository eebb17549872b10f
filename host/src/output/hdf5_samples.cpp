#include "nonsep/host/output/hdf5_samples.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
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

// The chunk shape of `dataset` when its filters are shuffle then deflate (what ShuffleDeflate writes); empty when
// not.
std::vector<hsize_t> shuffled_deflated_chunk(const Hdf5File& file, hid_t dataset, const char* name) {
  const std::string what = std::string("read the filters of ") + samples_group + "/" + name;
  const Hdf5Handle properties = file.own(H5Dget_create_plist(dataset), H5Pclose, what);
  if (H5Pget_layout(properties.get()) != H5D_CHUNKED || H5Pget_nfilters(properties.get()) != 2) return {};
  for (const auto& [index, filter] : {std::pair{0u, H5Z_FILTER_SHUFFLE}, std::pair{1u, H5Z_FILTER_DEFLATE}}) {
    unsigned flags = 0;
    std::size_t parameters = 0;
    if (H5Pget_filter2(properties.get(), index, &flags, &parameters, nullptr, 0, nullptr, nullptr) != filter) return {};
  }
  std::vector<hsize_t> chunk(3);
  chunk.resize(static_cast<std::size_t>(file.check(H5Pget_chunk(properties.get(), 3, chunk.data()), what)));
  return chunk;
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
  datasets.chunk_ = state_chunk;
  if (transfer == H5P_DEFAULT) datasets.filter_ = std::make_unique<ShuffleDeflate>(hdf5_deflate_level);
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
  // Written directly only when every chunk has the shape and filters this file's creator gave it.
  const std::vector<hsize_t> chunk = shuffled_deflated_chunk(file, datasets.q_.get(), "q");
  if (chunk.size() == 3 && chunk[2] == q[2] && shuffled_deflated_chunk(file, datasets.p_.get(), "p") == chunk &&
      shuffled_deflated_chunk(file, datasets.H_.get(), "H") == std::vector<hsize_t>{chunk[0], chunk[1]}) {
    datasets.chunk_ = {chunk[0], chunk[1], chunk[2]};
    datasets.filter_ = std::make_unique<ShuffleDeflate>(hdf5_deflate_level);
  }
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
  if (filter_ && whole_chunks(slab)) {
    write_chunks(q_.get(), "q", slab, slab.q, l.dimension);
    write_chunks(p_.get(), "p", slab, slab.p, l.dimension);
    write_chunks(H_.get(), "H", slab, slab.H, 1);
    return;
  }
  const std::array<hsize_t, 3> start{slab.first_sample, slab.first_trajectory, 0},
      count{slab.samples, slab.trajectories, l.dimension};
  write_block(*file_, q_.get(), "q", start, count, slab.q, transfer_);
  write_block(*file_, p_.get(), "p", start, count, slab.p, transfer_);
  write_block(*file_, H_.get(), "H", std::span(start).first<2>(), std::span(count).first<2>(), slab.H, transfer_);
}

bool SampleDatasets::whole_chunks(const SampleSlab& slab) const {
  const auto whole = [](std::uint64_t first, std::uint64_t count, std::uint64_t extent, hsize_t chunk) {
    return count > 0 && first % chunk == 0 && (count % chunk == 0 || first + count == extent);
  };
  return whole(slab.first_sample, slab.samples, layout_.samples, chunk_[0]) &&
         whole(slab.first_trajectory, slab.trajectories, layout_.trajectories, chunk_[1]);
}

void SampleDatasets::write_chunks(hid_t dataset, const char* name, const SampleSlab& slab,
                                  std::span<const double> values, std::uint64_t numbers_per_cell) {
  const std::string what = std::string("write samples to ") + samples_group + "/" + name;
  const std::uint64_t samples_per_chunk = chunk_[0], trajectories_per_chunk = chunk_[1];
  const std::uint64_t end_sample = slab.first_sample + slab.samples;
  const std::uint64_t end_trajectory = slab.first_trajectory + slab.trajectories;
  for (std::uint64_t s0 = slab.first_sample; s0 < end_sample; s0 += samples_per_chunk)
    for (std::uint64_t t0 = slab.first_trajectory; t0 < end_trajectory; t0 += trajectories_per_chunk) {
      // The chunk, NaN (the fill value) where it reaches past the dataset's last sample or trajectory.
      chunk_values_.assign(samples_per_chunk * trajectories_per_chunk * numbers_per_cell,
                           std::numeric_limits<double>::quiet_NaN());
      const std::uint64_t trajectories = std::min(trajectories_per_chunk, end_trajectory - t0);
      for (std::uint64_t s = s0; s < std::min(s0 + samples_per_chunk, end_sample); ++s) {
        const auto from =
            values.begin() +
            static_cast<std::ptrdiff_t>(((s - slab.first_sample) * slab.trajectories + t0 - slab.first_trajectory) *
                                        numbers_per_cell);
        std::copy(
            from, from + static_cast<std::ptrdiff_t>(trajectories * numbers_per_cell),
            chunk_values_.begin() + static_cast<std::ptrdiff_t>((s - s0) * trajectories_per_chunk * numbers_per_cell));
      }
      const std::array<hsize_t, 3> offset{s0, t0, 0};
      write_filtered_chunk(*file_, dataset, offset,
                           std::span(reinterpret_cast<const unsigned char*>(chunk_values_.data()),
                                     chunk_values_.size() * sizeof(double)),
                           sizeof(double), *filter_, what);
    }
}

void SampleDatasets::read(std::uint64_t first_sample, std::uint64_t samples, std::span<double> q, std::span<double> p,
                          std::span<double> H) const {
  const SampleLayout& l = layout_;
  const std::uint64_t cells = samples * l.trajectories;
  if (first_sample + samples > l.samples || q.size() != cells * l.dimension || p.size() != cells * l.dimension ||
      H.size() != cells)
    file_->fail("read samples " + std::to_string(first_sample) + " + " + std::to_string(samples) + " of " +
                std::to_string(l.samples) + " into " + std::to_string(q.size()) + " numbers of q");
  if (cells == 0) return;
  const std::array<hsize_t, 3> start{first_sample, 0, 0}, count{samples, l.trajectories, l.dimension};
  // H's rank is 2: its selection takes the first two numbers of start and count.
  for (const auto& [dataset, name, values] :
       {std::tuple{q_.get(), "q", q}, std::tuple{p_.get(), "p", p}, std::tuple{H_.get(), "H", H}}) {
    const std::string what = std::string("read samples of ") + samples_group + "/" + name;
    const Hdf5Handle space = file_->own(H5Dget_space(dataset), H5Sclose, what);
    file_->check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr), what);
    const hsize_t size = values.size();
    const Hdf5Handle memory = file_->own(H5Screate_simple(1, &size, nullptr), H5Sclose, what);
    file_->check(H5Dread(dataset, H5T_NATIVE_DOUBLE, memory.get(), space.get(), H5P_DEFAULT, values.data()), what);
  }
}

}  // namespace nonsep::host
