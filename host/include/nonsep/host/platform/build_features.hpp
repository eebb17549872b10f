#pragma once
// What this build of nonsep can do beyond the core: MPI ranks and HDF5 output (cmake/NonsepDependencies.cmake,
// options NONSEP_WITH_MPI and NONSEP_WITH_HDF5). `nonsep --version` prints build_features_text().
#include <string>

namespace nonsep::host {

bool built_with_mpi();
bool built_with_hdf5();
// "nonsep 0.1.0\nMPI: Open MPI v4.1.4 ...\nHDF5: 1.10.8 (parallel, MPI-IO)"; "MPI: not built (...)" otherwise.
std::string build_features_text();

}  // namespace nonsep::host
