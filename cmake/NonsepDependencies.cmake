# Third-party libraries, all from Debian 12 packages (scripts/setup.sh installs them).
find_package(Boost 1.74 REQUIRED)                     # libboost-dev: DLL, Math quadrature, Odeint (headers)
find_package(nlohmann_json 3.11 REQUIRED)             # nlohmann-json3-dev
find_package(CLI11 2.1 REQUIRED)                      # libcli11-dev
find_package(Threads REQUIRED)
find_package(OpenMP 4.5 REQUIRED COMPONENTS CXX)      # libgomp (comes with g++): the host's ensemble threads
if(BUILD_TESTING OR NOT DEFINED BUILD_TESTING) # tests are on unless -DBUILD_TESTING=OFF
  find_package(doctest 2.4 REQUIRED)                  # doctest-dev
  find_package(Eigen3 3.4 REQUIRED NO_MODULE)         # libeigen3-dev: the tests' linear algebra (the product has none)
endif()

# Python is used by tests and the figure scripts with modules from Debian packages (python3-jsonschema,
# python3-matplotlib), which live in the system interpreter. Prefer it over another python3 earlier on PATH
# (pyenv, a virtualenv) unless the user chose one with -DPython3_EXECUTABLE.
if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python interpreter with the Debian python3-* modules")
endif()
find_package(Python3 COMPONENTS Interpreter)
