# find_package(nonsep) pointed at nonsep's build tree (a new user's guess instead of an installed prefix) must
# fail with a message that says to install first, not with the installed config's "//lib/nonsep/plugins does not
# exist". Run by ctest as
#   cmake -DBUILD_DIR=... -DWORK_DIR=... -DCXX_COMPILER=... -P build_tree_package_test.cmake
foreach(variable BUILD_DIR WORK_DIR)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "build_tree_package_test.cmake: ${variable} is not set")
  endif()
endforeach()

file(REMOVE_RECURSE "${WORK_DIR}")
file(WRITE "${WORK_DIR}/source/CMakeLists.txt" "cmake_minimum_required(VERSION 3.25)
project(user_model LANGUAGES CXX)
find_package(nonsep 0.1 REQUIRED)
")
set(compiler_option)
if(DEFINED CXX_COMPILER)
  set(compiler_option -DCMAKE_CXX_COMPILER=${CXX_COMPILER})
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} -S "${WORK_DIR}/source" -B "${WORK_DIR}/build" "-DCMAKE_PREFIX_PATH=${BUILD_DIR}"
          ${compiler_option}
  RESULT_VARIABLE status OUTPUT_VARIABLE output ERROR_VARIABLE output)
if(status EQUAL 0)
  message(FATAL_ERROR "find_package(nonsep) accepted the build tree ${BUILD_DIR} as a package:\n${output}")
endif()
string(REGEX REPLACE "[ \t\r\n]+" " " flat "${output}")
foreach(expected "is nonsep's build tree, not an installed nonsep" "cmake --install" "-DCMAKE_PREFIX_PATH=PREFIX")
  string(FIND "${flat}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the refusal does not say \"${expected}\":\n${output}")
  endif()
endforeach()
string(FIND "${flat}" "does not exist" at)
if(NOT at EQUAL -1)
  message(FATAL_ERROR "the installed config ran in the build tree:\n${output}")
endif()
message(STATUS "find_package(nonsep) on the build tree refuses with: ${flat}")
