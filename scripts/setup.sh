#!/usr/bin/env bash
# Installs what nonsep needs from Debian 12 packages (as root; quick when everything is already there),
# then configures and builds the project in ./build with 2 parallel jobs.
# What is built: when ./build is configured for the first time, only what a user runs: the nonsep executable, the
# shipped plugins, the SDK and CMake package, the Python package and the example programs (BUILD_TESTING and
# NONSEP_BUILD_BENCHMARKS off). scripts/test.sh passes -DBUILD_TESTING=ON to build the test suites too (benchmarks
# stay off there: docs/performance.md builds them with -DNONSEP_BUILD_BENCHMARKS=ON). An existing ./build keeps its
# choice; options given here win over both.
# Usage: bash scripts/setup.sh [extra cmake -D options...]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  ca-certificates cmake g++ make pkg-config
  libeigen3-dev libboost-dev nlohmann-json3-dev doctest-dev libcli11-dev
  python3 python3-jsonschema python3-matplotlib python3-numpy python3-h5py
  python3-sympy  # tests/python/test_formula.py: nonsep.formula with SymPy expressions (docs/formula-models.md)
  jupyter-nbconvert python3-nbconvert python3-nbformat python3-ipykernel  # examples/tutorial.ipynb, run headless
  libopenmpi-dev openmpi-bin libhdf5-openmpi-dev hdf5-tools  # MPI ranks, parallel HDF5 output (docs/cluster.md)
  zlib1g-dev  # results.h5: /samples' chunks deflated by nonsep (host/include/nonsep/host/output/shuffle_deflate.hpp)
  clang libclang-rt-14-dev valgrind  # CI: fuzzing (tests/fuzz) and memcheck (tests/ci)
  clang-format-14  # tests: the code follows .clang-format (tests/check_format.sh)
  libgsl-dev  # benchmark-only (GPL): the peer integrators of bench/peers; nothing in the product links it
)
missing=()
for package in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

product_only=()
[ -f build/CMakeCache.txt ] || product_only=(-DBUILD_TESTING=OFF -DNONSEP_BUILD_BENCHMARKS=OFF)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${product_only[@]}" "$@" >/dev/null
cmake --build build -j2
