# nonsep_add_model(<target> [OUTPUT_DIRECTORY <dir>] <sources>...)
#
# Builds a nonsep model plugin: a MODULE library named exactly <target>.so (no "lib" prefix), all symbols hidden
# except the entry point NONSEP_EXPORT_MODEL defines, linked to nonsep::sdk (and through it nonsep::core, the static
# PIC library whose Integrator the SDK's integrate() runs inside the plugin; its symbols stay private to the
# plugin), unloadable (no GNU unique symbols). The plugin's metadata name must equal
# <target>. Used in the nonsep tree (shipped plugins land in NONSEP_BUILD_PLUGIN_DIR, the folder the host
# searches last) and by installed users after find_package(nonsep) (the plugin lands in the current binary
# folder; point NONSEP_PLUGIN_PATH at it, or load it by path).
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
  # GCC marks static locals of inline functions STB_GNU_UNIQUE, which makes glibc refuse to ever unload the
  # library; a plugin's symbols are private to it, so uniqueness buys nothing and unloading must work.
  target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-gnu-unique>)
  target_link_libraries(${target} PRIVATE nonsep::sdk)
  # The static libraries linked in (nonsep::core) export nothing from the plugin: the host has its own copy.
  target_link_options(${target} PRIVATE "LINKER:--exclude-libs,ALL")
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
