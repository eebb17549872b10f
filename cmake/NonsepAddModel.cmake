# nonsep_add_model(<target> [OUTPUT_DIRECTORY <dir>] <sources>...)
#
# Builds a nonsep model plugin: a MODULE library named exactly <target>.so (no "lib" prefix) whose metadata name
# must equal <target>. Only the symbol `nonsep_plugin` that NONSEP_EXPORT_MODEL (plugin_sdk.hpp) or
# NONSEP_DEFINE_PLUGIN (plugin_abi.h) defines is exported; everything else is hidden. It uses nonsep::sdk, which is
# header-only: no nonsep library is linked into a plugin (the host steps; a plugin only evaluates, plugin_abi.h).
#
# Unloading: GCC marks static locals of inline functions (the SDK's metadata string) STB_GNU_UNIQUE, which makes
# glibc refuse to ever unload the library; -fno-gnu-unique keeps a plugin unloadable (tests/plugins/
# test_plugin_lifetime.cpp). A plugin's symbols are private to it, so uniqueness buys nothing.
#
# Optimised by default: when the project sets no CMAKE_BUILD_TYPE (and the generator has a single configuration),
# the plugin is built with -O3 -DNDEBUG, the flags of a Release build and of the shipped plugins, and a STATUS
# message says so. Without this, CMake's empty build type compiles with no optimisation at all, and a model runs
# several times slower than the shipped ones for no visible reason.
#
# Used in the nonsep tree (shipped plugins land in NONSEP_BUILD_PLUGIN_DIR, the folder the host searches last) and
# by installed users after find_package(nonsep) (the plugin lands in the current binary folder; point
# NONSEP_PLUGIN_PATH at it, or load it by path).
function(nonsep_add_model target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "OUTPUT_DIRECTORY" "")
  if(NOT arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "nonsep_add_model(${target}): no source files given")
  endif()
  add_library(${target} MODULE ${arg_UNPARSED_ARGUMENTS})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    SUFFIX ".so"
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  target_compile_features(${target} PRIVATE cxx_std_20)
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique>)
  target_link_libraries(${target} PRIVATE nonsep::sdk)
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
