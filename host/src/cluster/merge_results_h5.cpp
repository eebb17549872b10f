#include "nonsep/host/cluster/merge_results_h5.hpp"

#include <optional>
#include <string>

#ifdef NONSEP_HAVE_MPI
#include <mpi.h>
#endif

#include "nonsep/host/observers/hdf5_sample_writer.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/hdf5_file.hpp"
#include "nonsep/host/output/hdf5_samples.hpp"

namespace nonsep::host {

namespace {

std::vector<double> read_all(const Hdf5File& file, const char* name, std::size_t count) {
  const std::string path = std::string(samples_group) + "/" + name;
  const Hdf5Handle dataset = file.own(H5Dopen2(file.id(), path.c_str(), H5P_DEFAULT), H5Dclose, "open " + path);
  std::vector<double> values(count);
  file.check(H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), "read " + path);
  return values;
}

}  // namespace

void merge_samples_h5(const std::filesystem::path& path, const LoadedJob& loaded, std::span<const UnitRange> units,
                      const Ranks& ranks) {
  const SingleRun& run = loaded.job.run();
  const std::vector<std::uint64_t> steps = Hdf5SampleWriter::sample_steps(run.time.steps, run.every);
  std::vector<double> times;
  for (std::uint64_t step : steps) times.push_back(run.time.time_at(step));
  const SampleLayout layout{steps.size(), loaded.job.initial.count, loaded.job.initial.dimension};

  hid_t access = H5P_DEFAULT, transfer = H5P_DEFAULT;
#if defined(NONSEP_HAVE_MPI) && defined(H5_HAVE_PARALLEL)
  if (ranks.joined_mpi()) {
    access = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_fapl_mpio(access, MPI_COMM_WORLD, MPI_INFO_NULL);
    transfer = H5Pcreate(H5P_DATASET_XFER);
    H5Pset_dxpl_mpio(transfer, H5FD_MPIO_COLLECTIVE);
  }
#endif
  struct Properties {
    hid_t access, transfer;
    ~Properties() {
      if (access != H5P_DEFAULT) H5Pclose(access);
      if (transfer != H5P_DEFAULT) H5Pclose(transfer);
    }
  } properties{access, transfer};

  Hdf5File file = Hdf5File::create(path, access);
  std::optional<SampleDatasets> samples = SampleDatasets::create(file, layout, steps, times, transfer);
  std::optional<OutputError> failure;
  const std::size_t size = static_cast<std::size_t>(ranks.size());
  for (std::size_t round = 0; round * size < units.size(); ++round) {
    const std::size_t unit = round * size + static_cast<std::size_t>(ranks.rank());
    std::vector<double> q, p, H;
    SampleSlab slab;  // empty: this rank's part of the round's collective write when it has no unit or failed
    if (unit < units.size() && !failure) {
      try {
        const UnitRange& range = units[unit];
        const Hdf5File part = Hdf5File::open(range.folder / "results.h5");
        const SampleLayout expected{layout.samples, range.size, layout.dimension};
        if (SampleDatasets::open(part).layout() != expected)
          part.fail("use its /samples: not the layout of trajectories " + std::to_string(range.first) + " + " +
                    std::to_string(range.size) + " of this run");
        const std::size_t cells = layout.samples * range.size;
        q = read_all(part, "q", cells * layout.dimension);
        p = read_all(part, "p", cells * layout.dimension);
        H = read_all(part, "H", cells);
        slab = {0, layout.samples, range.first, range.size, q, p, H};
      } catch (const OutputError& error) {
        failure = error;
      }
    }
    samples->write(slab);
  }
  samples.reset();  // its datasets close before the file (collectively, in the same order on every rank)
  file.close();
  if (failure) throw *failure;
}

}  // namespace nonsep::host
