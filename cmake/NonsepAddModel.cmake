# nonsep_add_model(<target> [OUTPUT_DIRECTORY <dir>] [TANGENT_KERNELS]
#                  [KERNEL_SETS native|native+baseline|all|baseline] <sources>...)
#
# Builds a nonsep model plugin: a MODULE library named exactly <target>.so (no "lib" prefix) whose metadata name
# must equal <target>. Only the symbol `nonsep_plugin` that NONSEP_EXPORT_MODEL (plugin_sdk.hpp) or
# NONSEP_DEFINE_PLUGIN (plugin_abi.h) defines is exported; everything else is hidden. It links nonsep::sdk, the SDK's
# headers and its small static library of JSON reading and writing (plugins/CMakeLists.txt), and no other nonsep
# library (the host steps; a plugin evaluates, and carries kernels compiled from the core's headers: plugin_abi.h).
#
# Unloading: GCC marks static locals of inline functions (the SDK's metadata string) STB_GNU_UNIQUE, which makes
# glibc refuse to ever unload the library; -fno-gnu-unique keeps a plugin unloadable (tests/plugins/
# test_plugin_lifetime.cpp). A plugin's symbols are private to it, so uniqueness buys nothing.
#
# KERNEL_SETS chooses the stepping kernels compiled (nonsep/sdk/kernels.hpp), each set a large part of the compile
# time: `native` (the default, or NONSEP_KERNEL_SETS when set) the widest set the building machine runs alone,
# x86-64-v4 or x86-64-v3, found once per build folder by running a probe (the baseline x86-64 where it runs neither,
# and the baseline with both wider sets where the probe cannot run: another compiler, cross-compiling), since the host
# never takes the baseline over a wider set the processor runs; `native+baseline` that set and the baseline, which
# NONSEP_INSTRUCTION_SET=baseline runs (bit for bit the evaluation path: the doctests pin it, tests/test_main.cpp);
# `all` the baseline and both wider sets, for plugins that run on other machines than the one that builds them;
# `baseline` the baseline alone. The host picks the widest kernel the plugin has and the processor runs
# (NONSEP_INSTRUCTION_SET overrides), and steps through the evaluation path where it runs none of them.
#
# A one-file plugin that exports its model with NONSEP_EXPORT_MODEL, built with GCC on x86-64, is compiled as
# translation units that make can run in parallel:
# the plugin with its baseline kernels (where it has them), and its x86-64-v3 and x86-64-v4 kernels each in a unit of its own
# (${target}_kernel_unit_1.cpp and _2.cpp in the binary folder, which include the source; nonsep/sdk/kernels.hpp,
# "Kernel units"). The plugin is the same; on two cores it builds in about two thirds of the wall time
# (docs/writing-models.md, "How long a plugin takes to build"). Several sources are compiled as they are.
#
# -fno-math-errno: the math functions do not set errno (nothing in a plugin reads it), which changes no number but
# lets the compiler treat them as pure. Then a gradient by automatic differentiation drops the calls only the value
# of T or V needs (asinh in T = asinh(p) + ...), and sqrt vectorizes across a block of states (docs/writing-models.md,
# "How fast automatic derivatives are").
#
# Optimised by default: when the project sets no CMAKE_BUILD_TYPE (and the generator has a single configuration),
# the plugin is built with -O3 -DNDEBUG, the flags of a Release build and of the shipped plugins, and a STATUS
# message says so. Without this, CMake's empty build type compiles with no optimisation at all, and a model runs
# several times slower than the shipped ones for no visible reason.
#
# Used in the nonsep tree (shipped plugins land in NONSEP_BUILD_PLUGIN_DIR, the folder the host searches last) and
# by installed users after find_package(nonsep) (the plugin lands in the current binary folder; point
# NONSEP_PLUGIN_PATH at it, or load it by path).
# The bits of NONSEP_SDK_WIDE_KERNEL_SETS (1: x86-64-v3, 2: x86-64-v4) of the widest set this machine runs, into
# `out`; probed once per build folder (the same test as the host's kernel choice), and 3 (both) where the probe
# cannot run (another compiler than GCC or clang, cross-compiling).
function(_nonsep_native_kernel_sets out)
  if(NOT DEFINED NONSEP_NATIVE_KERNEL_SETS)
    set(probe "${CMAKE_BINARY_DIR}/CMakeFiles/nonsep_kernel_probe.cpp")
    file(WRITE "${probe}" [=[
#include <cstdio>
int main() {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  const bool v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
                  __builtin_cpu_supports("bmi2");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
  std::printf("%d", v4 ? 2 : v3 ? 1 : 0);
#else
  std::printf("0");
#endif
}
]=])
    try_run(probe_ran probe_compiled "${CMAKE_BINARY_DIR}/CMakeFiles/nonsep_kernel_probe" "${probe}"
            RUN_OUTPUT_VARIABLE sets)
    if(NOT probe_compiled OR NOT probe_ran EQUAL 0 OR NOT sets MATCHES "^[0-2]$")
      set(sets 3)
    endif()
    set(NONSEP_NATIVE_KERNEL_SETS ${sets} CACHE INTERNAL "nonsep_add_model: the wider kernel sets this machine runs")
  endif()
  set(${out} ${NONSEP_NATIVE_KERNEL_SETS} PARENT_SCOPE)
endfunction()

function(nonsep_add_model target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "TANGENT_KERNELS" "OUTPUT_DIRECTORY;KERNEL_SETS" "")
  if(NOT arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "nonsep_add_model(${target}): no source files given")
  endif()
  if(NOT arg_KERNEL_SETS)
    set(arg_KERNEL_SETS native)
    if(NONSEP_KERNEL_SETS)
      set(arg_KERNEL_SETS ${NONSEP_KERNEL_SETS})
    endif()
  endif()
  set(baseline_kernels 1)
  if(arg_KERNEL_SETS MATCHES "^native(\\+baseline)?$")
    _nonsep_native_kernel_sets(wide_sets)
    if(arg_KERNEL_SETS STREQUAL "native" AND (wide_sets EQUAL 1 OR wide_sets EQUAL 2))
      set(baseline_kernels 0)
    endif()
  elseif(arg_KERNEL_SETS STREQUAL "all")
    set(wide_sets 3)
  elseif(arg_KERNEL_SETS STREQUAL "baseline")
    set(wide_sets 0)
  else()
    message(FATAL_ERROR "nonsep_add_model(${target}): KERNEL_SETS \"${arg_KERNEL_SETS}\" (NONSEP_KERNEL_SETS?); "
                        "allowed: native, native+baseline, all or baseline")
  endif()
  add_library(${target} MODULE ${arg_UNPARSED_ARGUMENTS})
  list(LENGTH arg_UNPARSED_ARGUMENTS source_count)
  # Only a source that exports its model with NONSEP_EXPORT_MODEL is split: there the macro expands to the kernel
  # unit's function in a unit. A source that defines its own table (NONSEP_DEFINE_PLUGIN) is compiled whole.
  set(splittable FALSE)
  if(source_count EQUAL 1 AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_SYSTEM_PROCESSOR MATCHES "x86_64|AMD64")
    get_filename_component(source "${arg_UNPARSED_ARGUMENTS}" ABSOLUTE)
    file(READ "${source}" source_text)
    string(FIND "${source_text}" "NONSEP_EXPORT_MODEL" exports_model)
    string(FIND "${source_text}" "NONSEP_DEFINE_PLUGIN" defines_table)
    if(NOT exports_model EQUAL -1 AND defines_table EQUAL -1)
      set(splittable TRUE)
    endif()
  endif()
  if(splittable)
    # The wider kernel sets in translation units of their own, compiled in parallel with the rest
    # (nonsep/sdk/kernels.hpp, "Kernel units"): each unit includes the one source with NONSEP_SDK_KERNEL_UNIT set.
    set(units "")
    foreach(unit 1 2)
      math(EXPR wanted "${wide_sets} & ${unit}")
      if(NOT wanted)
        continue()
      endif()
      set(unit_file "${CMAKE_CURRENT_BINARY_DIR}/${target}_kernel_unit_${unit}.cpp")
      math(EXPR level "${unit} + 2")
      file(CONFIGURE OUTPUT "${unit_file}"
           CONTENT "// Generated by nonsep_add_model: the x86-64-v${level} kernels of ${target} (nonsep/sdk/kernels.hpp).\n#define NONSEP_SDK_KERNEL_UNIT ${unit}\n#include \"${source}\"\n"
           @ONLY)
      list(APPEND units "${unit_file}")
    endforeach()
    target_sources(${target} PRIVATE ${units})
    set_property(SOURCE "${source}" TARGET_DIRECTORY ${target} APPEND PROPERTY COMPILE_DEFINITIONS
                 NONSEP_SDK_SEPARATE_KERNEL_UNITS=${wide_sets})
  endif()
  target_compile_definitions(${target} PRIVATE NONSEP_SDK_WIDE_KERNEL_SETS=${wide_sets}
                                               NONSEP_SDK_BASELINE_KERNELS=${baseline_kernels})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    SUFFIX ".so"
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_features(${target} PRIVATE cxx_std_20)
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique> -fno-math-errno)
  target_link_libraries(${target} PRIVATE nonsep::sdk)
  if(arg_TANGENT_KERNELS)
    # The tangent kernels (chin_tangent_steps, nonsep/sdk/kernels.hpp): fast Lyapunov/MEGNO/SALI/GALI runs of Chin's
    # schemes, at about five times the plugin's compile time.
    target_compile_definitions(${target} PRIVATE NONSEP_SDK_TANGENT_KERNELS=1)
  endif()
  get_property(multi_config GLOBAL PROPERTY GENERATOR_IS_MULTI_CONFIG)
  if(NOT multi_config AND NOT CMAKE_BUILD_TYPE)
    target_compile_options(${target} PRIVATE -O3)
    target_compile_definitions(${target} PRIVATE NDEBUG)
    message(STATUS "nonsep_add_model(${target}): no CMAKE_BUILD_TYPE set, so the plugin is built optimised "
                   "(-O3 -DNDEBUG, as Release and the shipped plugins); set CMAKE_BUILD_TYPE to choose otherwise")
  endif()
  if(arg_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${arg_OUTPUT_DIRECTORY}")
  elseif(DEFINED NONSEP_BUILD_PLUGIN_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${NONSEP_BUILD_PLUGIN_DIR}")
  else()
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}")
  endif()
  if(TARGET nonsep_warnings)
    target_link_libraries(${target} PRIVATE nonsep_warnings)
  endif()
endfunction()
