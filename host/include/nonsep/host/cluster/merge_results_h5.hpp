#pragma once
// results.h5 of a distributed run (output.format "hdf5"; distributed_run.hpp): every work unit wrote its own
// results.h5; the ranks copy the units' /samples into the run's results.h5 together, through MPI-IO (HDF5's
// collective writes, which its compressed datasets require), each rank the units r, r + size, r + 2 size, ... (a
// static split: the copy is I/O, the same amount per unit). Rank 0 then adds the tables and attributes from the
// merged CSV files and summary (output/results_h5.hpp), as one process does. The numbers equal one process's; the
// file's bytes may not (HDF5 places chunks in the order they are written).
#include <cstddef>
#include <filesystem>
#include <vector>

#include "nonsep/host/cluster/ranks.hpp"
#include "nonsep/host/job.hpp"

namespace nonsep::host {

struct UnitRange {
  std::filesystem::path folder;
  std::size_t first = 0, size = 0;
};

// Collective: every rank calls it with the same arguments. Writes `path`'s /samples from the units' results.h5.
// Throws OutputError on the rank that failed, after every rank has taken its part in the collective writes.
void merge_samples_h5(const std::filesystem::path& path, const LoadedJob& loaded, std::span<const UnitRange> units,
                      const Ranks& ranks);

}  // namespace nonsep::host
