# Third-party libraries, all from Debian 12 packages (scripts/setup.sh installs them).
find_package(Boost 1.74 REQUIRED)                     # libboost-dev: DLL, Math quadrature, Odeint (headers)
find_package(nlohmann_json 3.11 REQUIRED)             # nlohmann-json3-dev
find_package(CLI11 2.1 REQUIRED)                      # libcli11-dev
find_package(Eigen3 3.4 REQUIRED NO_MODULE)           # libeigen3-dev: the FFT of frequency analysis; the tests' linear algebra
find_package(Threads REQUIRED)
find_package(OpenMP 4.5 REQUIRED COMPONENTS CXX)      # libgomp (comes with g++): the host's ensemble threads
if(BUILD_TESTING OR NOT DEFINED BUILD_TESTING) # tests are on unless -DBUILD_TESTING=OFF
  find_package(doctest 2.4 REQUIRED)                  # doctest-dev
endif()

# Python is used by tests and the figure scripts with modules from Debian packages (python3-jsonschema,
# python3-matplotlib), which live in the system interpreter. Prefer it over another python3 earlier on PATH
# (pyenv, a virtualenv) unless the user chose one with -DPython3_EXECUTABLE.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter with the Debian python3-* modules")
endif()
find_package(Python3 COMPONENTS Interpreter)

# Ensembles beyond one machine (docs/cluster.md): MPI ranks (libopenmpi-dev) and HDF5 output (libhdf5-dev; under MPI
# the parallel build libhdf5-openmpi-dev, so that the ranks write results.h5 through MPI-IO). Both on by default;
# a build without them still runs everything else and says so in `nonsep --version`.
option(NONSEP_WITH_MPI "Distribute `nonsep run` ensembles over MPI ranks (OpenMPI)" ON)
option(NONSEP_WITH_HDF5 "output.format \"hdf5\": results.h5 (HDF5 C library)" ON)
if(NONSEP_WITH_MPI OR NONSEP_WITH_HDF5)
  enable_language(C)  # FindMPI and FindHDF5 probe the C libraries with the C compiler
endif()
if(NONSEP_WITH_MPI)
  find_package(MPI 3.1 REQUIRED COMPONENTS C)         # libopenmpi-dev
endif()
if(NONSEP_WITH_HDF5)
  set(HDF5_PREFER_PARALLEL ${NONSEP_WITH_MPI})
  find_package(HDF5 1.10.2 REQUIRED COMPONENTS C)     # libhdf5-openmpi-dev (with MPI) or libhdf5-dev; H5Dwrite_chunk
  find_package(ZLIB REQUIRED)                         # zlib1g-dev: results.h5's /samples chunks (shuffle_deflate.hpp)
  if(NONSEP_WITH_MPI AND NOT HDF5_IS_PARALLEL)
    message(FATAL_ERROR "NONSEP_WITH_MPI needs the parallel HDF5 build (Debian: libhdf5-openmpi-dev); found a "
                        "serial one at ${HDF5_INCLUDE_DIRS}. Install it, or configure with -DNONSEP_WITH_HDF5=OFF.")
  endif()
  if(NOT NONSEP_WITH_MPI AND HDF5_IS_PARALLEL)
    message(FATAL_ERROR "HDF5 at ${HDF5_INCLUDE_DIRS} is the parallel build but NONSEP_WITH_MPI is OFF; install "
                        "the serial build (Debian: libhdf5-dev) or turn MPI on.")
  endif()
endif()
