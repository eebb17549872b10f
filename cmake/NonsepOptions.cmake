# Build options shared by every target of the project: language level, warnings, sanitizers,
# and the layout of the build tree (executables in build/bin, plugins in build/plugins).
set(CMAKE_CXX_STANDARD 20)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
set(CMAKE_CXX_VISIBILITY_PRESET hidden)
set(CMAKE_VISIBILITY_INLINES_HIDDEN ON)

if(NOT CMAKE_BUILD_TYPE AND NOT CMAKE_CONFIGURATION_TYPES)
  set(CMAKE_BUILD_TYPE Release CACHE STRING "Build type" FORCE)
endif()

set(CMAKE_RUNTIME_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/bin")
set(CMAKE_ARCHIVE_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/lib")
set(CMAKE_LIBRARY_OUTPUT_DIRECTORY "${PROJECT_BINARY_DIR}/lib")
# Shipped plugins land here; the host searches this folder last, as bin/../plugins from its executable (see
# host/loader: plugin_search_path).
set(NONSEP_BUILD_PLUGIN_DIR "${PROJECT_BINARY_DIR}/plugins")

option(NONSEP_SANITIZE "Build everything with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
# Compile everything (core, host, plugins, benchmarks) for the building machine's instruction set, SIMD included
# (-march=native). Off by default: binaries then run on any x86-64. See docs/performance.md, figure 2n.
option(NONSEP_NATIVE "Compile for this machine's instruction set (-march=native); binaries are not portable" OFF)
if(NONSEP_NATIVE)
  add_compile_options(-march=native)
endif()

# The stepping kernels of the plugins built here (nonsep_add_model's KERNEL_SETS): native (the widest set this machine
# runs, alone), native+baseline (and the baseline), all (the baseline, x86-64-v3 and x86-64-v4, for plugins that run
# elsewhere) or baseline. Empty, the default: native, or native+baseline in a build with the tests (BUILD_TESTING),
# whose doctests pin the baseline kernel (tests/test_main.cpp); the top-level CMakeLists.txt decides, after CTest.
set(NONSEP_KERNEL_SETS "" CACHE STRING
    "Plugin stepping kernels: native, native+baseline, all or baseline; empty: native (native+baseline with tests)")
set_property(CACHE NONSEP_KERNEL_SETS PROPERTY STRINGS "" native native+baseline all baseline)

option(NONSEP_WARNINGS_AS_ERRORS "Treat compiler warnings as errors" OFF)

add_library(nonsep_warnings INTERFACE)
# GCC 12 reports -Wrestrict inside libstdc++ for std::string's operator+ at -O2 and above (GCC bug 105329), and
# -Wstringop-overflow, -Wstringop-overread and -Warray-bounds inside char_traits<char>::copy for strings built from literals (a push_back
# of "max_abs_relative_energy_error" into a vector of strings is one): false positives of the same inlining, in seven
# of our files, none a bug (ASan and UBSan run the same code clean).
set(nonsep_gcc12 "$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>")
target_compile_options(nonsep_warnings INTERFACE -Wall -Wextra -Wpedantic
  $<$<BOOL:${NONSEP_WARNINGS_AS_ERRORS}>:-Werror>
  $<${nonsep_gcc12}:-Wno-restrict> $<${nonsep_gcc12}:-Wno-stringop-overflow> $<${nonsep_gcc12}:-Wno-stringop-overread>
  $<${nonsep_gcc12}:-Wno-array-bounds>)

if(NONSEP_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# libFuzzer harnesses for tests/fuzz (clang only). The harnesses link -fsanitize=fuzzer; the host's job-file and
# checkpoint reading, which they fuzz, is compiled with libFuzzer's coverage instrumentation (host/CMakeLists.txt),
# and nothing else is: the same build runs the sanitized test suite, whose integrations that instrumentation of
# every comparison would slow several times.
option(NONSEP_FUZZ "Build the libFuzzer harnesses of tests/fuzz (requires clang)" OFF)
if(NONSEP_FUZZ AND NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "NONSEP_FUZZ needs clang (CXX=clang++), not ${CMAKE_CXX_COMPILER_ID}")
endif()

# The host library's and the test suites' files spend most of their compile time in the compiler's front end, on
# the same headers (the JSON library, doctest, the core's templates, the standard library): each such target
# precompiles the headers its files share, once. Off: every file parses them itself (same program).
option(NONSEP_PRECOMPILE_HEADERS "Precompile the headers shared by the files of the host library and the test suites" ON)
function(nonsep_precompile_headers target)
  if(NONSEP_PRECOMPILE_HEADERS)
    target_precompile_headers(${target} PRIVATE ${ARGN})
  endif()
endfunction()

# The host library's and the test suites' files also share what they instantiate and optimise (the JSON library's
# and the core's templates), once per file: each such target is compiled as a few translation units that include
# its files (CMake's unity build), which takes a fraction of the CPU time. Off: one translation unit per file, for
# incremental work on one file.
option(NONSEP_UNITY_BUILD "Compile the host library and the test suites as a few translation units each" ON)
function(nonsep_unity_build target files_per_unit)
  if(NONSEP_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${files_per_unit})
  endif()
endfunction()
