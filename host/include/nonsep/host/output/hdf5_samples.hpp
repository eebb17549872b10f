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
// several samples of all of them; compressed with shuffle and deflate (level hdf5_deflate_level).
//
// SampleDatasets is the layout's only writer, for one process (Hdf5SampleWriter) or for ranks that each write their
// trajectories' slab into a file they opened with an MPI-IO access list. Throws OutputError (hdf5_file.hpp).
#include <cstdint>
#include <span>

#include "nonsep/host/output/hdf5_file.hpp"

namespace nonsep::host {

inline constexpr const char* samples_group = "/samples";
// deflate's level: on the benchmark's 10^5 paper2d trajectories (docs/performance.md) level 4 makes results.h5 0.9%
// smaller than level 1 (6: 1.2%) and takes 10% longer (the shuffled exponent bytes compress, the mantissas hardly).
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
  // Writes `slab`; OutputError when it reaches outside the layout or its spans have the wrong sizes.
  void write(const SampleSlab& slab);

 private:
  SampleDatasets(const Hdf5File& file) : file_(&file) {}
  const Hdf5File* file_;
  SampleLayout layout_;
  Hdf5Handle q_, p_, H_;
  hid_t transfer_ = H5P_DEFAULT;
};

}  // namespace nonsep::host
