#pragma once
// The end of a run with output.format "hdf5": results.h5 gets the run's tables and facts beside its /samples
// (observers/hdf5_sample_writer.hpp; without samples, output.every 0, the file is created here). Groups, each
// written by write_csv_table (output/hdf5_tables.hpp) from the CSV file of the same run:
//   /trajectories  trajectories.csv     /poincare  poincare.csv (when written)     /lyapunov  lyapunov.csv (when
//   written)
// Attributes of the root group, all from the run's summary (summary.json's content, launch/run_summary.hpp):
// nonsep_version, hdf5_version, format_version (1), model, plugin_version, parameters (JSON), integrator (JSON:
// summary.json's "integrator"), hamiltonian, dt, steps, t_end, every, dimension, trajectories, summary (summary.json's
// text). A resumed run replaces the groups and attributes its interrupted run wrote. Only in builds with HDF5.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "nonsep/host/output/run_files.hpp"

namespace nonsep::host {

inline constexpr std::uint64_t results_format_version = 1;

// Throws OutputError.
// The tables come from the CSV files in `directory`, the attributes from `summary`.
void write_results_file(const std::filesystem::path& path, bool has_samples, const std::filesystem::path& directory,
                        const nlohmann::ordered_json& summary);

}  // namespace nonsep::host
