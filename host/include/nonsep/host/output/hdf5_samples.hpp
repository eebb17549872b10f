#pragma once
// The samples of a run in results.h5: group /samples with
//   step [S]        uint64   the sample steps: 0, every, 2 every, ... and the last step (trajectory.csv's event rows)
//   t    [S]        float64  their times
//   q    [S, N, n]  float64  q of trajectory j at sample i: q[i, j, :]
//   p    [S, N, n]  float64
//   H    [S, N]     float64  H where it was evaluated
// for N trajectories of dimension n. Every number of q, p and H is NaN (the fill value) until written: where a
// trajectory was no longer active, H was not evaluated, or the run has not reached the sample yet.
// Chunks hold at most 65536 numbers (512 KiB): one sample of up to 65536/n trajectories, or, for small ensembles,
// several samples of all of them; compressed with shuffle and deflate (level hdf5_deflate_level). A slab made of
// whole chunks (all of a chunk's samples and trajectories that lie inside the dataset) written by one process is
// filtered by our code (shuffle_deflate.hpp, which stores the incompressible mantissa planes instead of deflating
// them) and written with H5Dwrite_chunk; any other slab, and every write of ranks sharing a file through MPI-IO
// (where HDF5 1.10 has no direct chunk writes), goes through HDF5's own filter pipeline. Both are read alike.
//
// SampleDatasets is the layout's only writer, for one process (Hdf5SampleWriter) or for ranks that each write their
// trajectories' slab into a file they opened with an MPI-IO access list. Throws OutputError (hdf5_file.hpp).
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "nonsep/host/output/hdf5_file.hpp"
#include "nonsep/host/output/shuffle_deflate.hpp"

namespace nonsep::host {

inline constexpr const char* samples_group = "/samples";
// deflate's level for the planes that are deflated: on the benchmark's 10^5 paper2d trajectories (docs/performance.md)
// level 4 makes results.h5 0.9% smaller than level 1 (6: 1.2%) and takes 10% longer (the shuffled exponent bytes
// compress, the mantissas hardly).
inline constexpr unsigned hdf5_deflate_level = 1;

struct SampleLayout {
  std::uint64_t samples = 0, trajectories = 0, dimension = 0;  // S, N, n
  friend bool operator==(const SampleLayout&, const SampleLayout&) = default;
};

// A block of consecutive samples and consecutive trajectories: q and p hold [samples][trajectories][dimension]
// numbers (row-major), H [samples][trajectories]; NaN for what is unknown.
struct SampleSlab {
  std::uint64_t first_sample = 0, samples = 0;
  std::uint64_t first_trajectory = 0, trajectories = 0;
  std::span<const double> q, p, H;
};

class SampleDatasets {
 public:
  // Creates /samples in `file` for `layout`, with step and t written (`steps` and `times`, S each) and q, p, H all
  // NaN. `transfer`: the data transfer list of every write (collective MPI-IO for ranks writing one file together:
  // then every rank calls create and each write, with an empty slab when it has nothing to write).
  static SampleDatasets create(const Hdf5File& file, const SampleLayout& layout, std::span<const std::uint64_t> steps,
                               std::span<const double> times, hid_t transfer = H5P_DEFAULT);
  // Opens /samples of `file`; OutputError when it is missing or not of this layout (names, types, ranks).
  static SampleDatasets open(const Hdf5File& file);

  const SampleLayout& layout() const { return layout_; }
  // The samples of a chunk: a writer that buffers this many rows of all trajectories writes whole chunks.
  std::uint64_t samples_per_chunk() const { return chunk_[0]; }
  // Writes `slab`; OutputError when it reaches outside the layout or its spans have the wrong sizes.
  void write(const SampleSlab& slab);
  // Reads samples [first_sample, first_sample + samples) of all trajectories into q and p ([samples][N][n]) and H
  // ([samples][N]). OutputError when they reach outside the layout or the spans have the wrong sizes.
  void read(std::uint64_t first_sample, std::uint64_t samples, std::span<double> q, std::span<double> p,
            std::span<double> H) const;

 private:
  SampleDatasets(const Hdf5File& file) : file_(&file) {}
  // Whether `slab` is made of whole chunks (see the top of this file).
  bool whole_chunks(const SampleSlab& slab) const;
  // Filters and writes the chunks of a whole-chunk slab of `dataset` ([S][N][numbers_per_cell]) from `values`.
  void write_chunks(hid_t dataset, const char* name, const SampleSlab& slab, std::span<const double> values,
                    std::uint64_t numbers_per_cell);

  const Hdf5File* file_;
  SampleLayout layout_;
  std::array<hsize_t, 3> chunk_{1, 1, 1};  // of q and p: samples, trajectories, dimension (H: the first two)
  Hdf5Handle q_, p_, H_;
  hid_t transfer_ = H5P_DEFAULT;
  std::unique_ptr<ShuffleDeflate> filter_;  // set when the chunks are written directly
  std::vector<double> chunk_values_;
};

}  // namespace nonsep::host
