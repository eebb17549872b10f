#include "nonsep/host/platform/build_features.hpp"

#ifdef NONSEP_HAVE_MPI
#include <mpi.h>
#endif
#ifdef NONSEP_HAVE_HDF5
#include <hdf5.h>
#endif

namespace nonsep::host {

bool built_with_mpi() {
#ifdef NONSEP_HAVE_MPI
  return true;
#else
  return false;
#endif
}

bool built_with_hdf5() {
#ifdef NONSEP_HAVE_HDF5
  return true;
#else
  return false;
#endif
}

std::string build_features_text() {
  std::string text = "nonsep " NONSEP_VERSION "\nMPI: ";
#ifdef NONSEP_HAVE_MPI
  char library[MPI_MAX_LIBRARY_VERSION_STRING];
  int length = 0;
  MPI_Get_library_version(library, &length);  // callable before MPI_Init
  std::string name(library, static_cast<std::size_t>(length));
  if (const auto end = name.find_first_of(",\n"); end != std::string::npos) name.resize(end);
  text += name + " (mpirun -n N nonsep run JOB.json: docs/cluster.md)";
#else
  text += "not built (configure with -DNONSEP_WITH_MPI=ON and libopenmpi-dev installed)";
#endif
  text += "\nHDF5: ";
#ifdef NONSEP_HAVE_HDF5
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  text += std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(release);
#ifdef H5_HAVE_PARALLEL
  text += " (parallel: MPI ranks write results.h5 through MPI-IO)";
#else
  text += " (serial)";
#endif
#else
  text += "not built (output.format \"hdf5\" unavailable; configure with -DNONSEP_WITH_HDF5=ON and libhdf5-dev)";
#endif
  return text;
}

}  // namespace nonsep::host
