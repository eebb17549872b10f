# Installs nonsep into a fresh prefix, builds examples/external_model against it as a user would (without a
# CMAKE_BUILD_TYPE, as a first CMake project often is: nonsep_add_model must then build it optimised and say so),
# checks that the package accepts a request for an older 0.x version, and loads the plugin it built. Run by ctest as
#   cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=... -DCHECK_PROGRAM=... -DCXX_COMPILER=...
#         -P external_model_test.cmake
foreach(variable BUILD_DIR SOURCE_DIR WORK_DIR CHECK_PROGRAM)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "external_model_test.cmake: ${variable} is not set")
  endif()
endforeach()

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "failed (${status}): ${ARGN}\n${output}")
  endif()
  set(last_output "${output}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")
run(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${prefix}")

foreach(installed
    bin/nonsep include/nonsep/plugin_abi.h include/nonsep/plugin_sdk.hpp include/nonsep/derivative_checker.hpp
    include/nonsep/host/plugin_loader.hpp lib/cmake/nonsep/nonsepConfig.cmake lib/cmake/nonsep/NonsepAddModel.cmake
    lib/nonsep/plugins/paper1d.so lib/nonsep/plugins/radial.so lib/nonsep/plugins/quadratic_kinetic.so
    lib/nonsep/plugins/tao_product.so)
  if(NOT EXISTS "${prefix}/${installed}")
    message(FATAL_ERROR "the install lacks ${installed}")
  endif()
endforeach()

# find_package(nonsep 0.1) keeps working across minor versions (SameMajorVersion): the installed version file
# accepts a request for an older minor version of the same major one, and refuses another major version.
function(version_accepts requested expected)
  set(PACKAGE_FIND_NAME nonsep)
  set(PACKAGE_FIND_VERSION "${requested}")
  string(REPLACE "." ";" parts "${requested}")
  list(GET parts 0 PACKAGE_FIND_VERSION_MAJOR)
  list(GET parts 1 PACKAGE_FIND_VERSION_MINOR)
  set(PACKAGE_FIND_VERSION_PATCH 0)
  set(PACKAGE_FIND_VERSION_COUNT 2)
  include("${prefix}/lib/cmake/nonsep/nonsepConfigVersion.cmake")
  if(NOT PACKAGE_VERSION_COMPATIBLE STREQUAL "${expected}")
    message(FATAL_ERROR "the installed nonsep ${PACKAGE_VERSION} says compatible = '${PACKAGE_VERSION_COMPATIBLE}' "
                        "for find_package(nonsep ${requested}); expected ${expected}")
  endif()
endfunction()
version_accepts(0.0 TRUE)
version_accepts(0.1 TRUE)
version_accepts(1.0 FALSE)

run(${CMAKE_COMMAND} -S "${SOURCE_DIR}/examples/external_model" -B "${WORK_DIR}/build"
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)
set(optimised "nonsep_add_model\\(relativistic_pendulum\\): no CMAKE_BUILD_TYPE set, so the plugin is built optimised")
if(NOT last_output MATCHES "${optimised}")
  message(FATAL_ERROR "configuring the example without CMAKE_BUILD_TYPE did not say it builds optimised:\n"
                      "${last_output}")
endif()
# The flags actually used: the plugin's source is compiled with -O2 or -O3.
file(READ "${WORK_DIR}/build/compile_commands.json" commands)
string(JSON command_count LENGTH "${commands}")
set(plugin_command "")
math(EXPR last_command "${command_count} - 1")
foreach(k RANGE ${last_command})
  string(JSON source GET "${commands}" ${k} file)
  if(source MATCHES "relativistic_pendulum\\.cpp$")
    string(JSON plugin_command GET "${commands}" ${k} command)
  endif()
endforeach()
if(NOT plugin_command MATCHES " -O[23]( |$)")
  message(FATAL_ERROR "without CMAKE_BUILD_TYPE the example plugin is not compiled optimised: ${plugin_command}")
endif()
run(${CMAKE_COMMAND} --build "${WORK_DIR}/build" -j2)
set(plugin "${WORK_DIR}/build/relativistic_pendulum.so")
if(NOT EXISTS "${plugin}")
  message(FATAL_ERROR "the example did not produce ${plugin}")
endif()
run("${CHECK_PROGRAM}" "${plugin}")
message(STATUS "${last_output}")

# The installed host: it finds the shipped models in the install's plugin folder (NONSEP_PLUGIN_PATH empty), and
# loads, checks and runs the model built outside the tree, named by path.
set(ENV{NONSEP_PLUGIN_PATH} "")
run("${prefix}/bin/nonsep" models)
foreach(model paper1d radial quadratic_kinetic tao_product)
  if(NOT last_output MATCHES "${model}  [^\n]*${prefix}/lib/nonsep/plugins/${model}\\.so")
    message(FATAL_ERROR "`nonsep models` of the install does not list ${model} from its plugin folder:\n${last_output}")
  endif()
endforeach()
run("${prefix}/bin/nonsep" inspect "${plugin}" --check)
if(NOT last_output MATCHES "relativistic_pendulum")
  message(FATAL_ERROR "`nonsep inspect --check` did not describe the plugin:\n${last_output}")
endif()
file(WRITE "${WORK_DIR}/pendulum.json" "{\"model\": {\"plugin\": \"build/relativistic_pendulum.so\"},
  \"integrator\": {\"scheme\": \"triplet\", \"order\": \"4/3\"}, \"initial\": {\"q\": [0.3], \"p\": [0.5]},
  \"time\": {\"dt\": 0.01, \"steps\": 1000}, \"output\": {\"every\": 100}}")
run("${prefix}/bin/nonsep" run --quiet "${WORK_DIR}/pendulum.json")
file(READ "${WORK_DIR}/pendulum.out/summary.json" summary)
string(JSON status GET "${summary}" status)
string(JSON error GET "${summary}" energy largest_relative_error value)
if(NOT status STREQUAL "completed" OR error GREATER 0.01)  # triplet 4/3 at dt = 0.01: about 1.1e-3
  message(FATAL_ERROR "the installed host's run of the external model: status ${status}, energy error ${error}")
endif()
message(STATUS "installed nonsep: models listed, external plugin checked and run (energy error ${error})")
