# Formula models (docs/formula-models.md): the host compiles them on first use with the compiler and flags of this
# build, described in share/nonsep/formula/toolchain.json, installed and in the build tree (NonsepShare.cmake):
#   {"compiler": "/usr/bin/c++", "flags": [...], "include_directories": [...]}
# Include folders are relative to the file's own folder (installed: <prefix>/include) or absolute (build tree: the
# SDK and core headers of the sources). The flags are those of a Release plugin (nonsep_add_model), never the
# build's own CMAKE_CXX_FLAGS: a sanitized build still compiles formula models without sanitizers, and a library
# without instrumentation loads into an instrumented process. A different compiler: NONSEP_CXX at run time.
# -O2, not the plugins' -O3: a user waits for the first compile, and -O3 added a sixth to it with no faster steps
# (docs/formula-models.md, "Measured").
# -fno-math-errno as for every plugin (NonsepAddModel.cmake).
set(NONSEP_FORMULA_FLAGS -std=c++20 -O2 -DNDEBUG -fno-math-errno -fPIC -shared -fvisibility=hidden
                         -fvisibility-inlines-hidden)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND NONSEP_FORMULA_FLAGS -fno-gnu-unique)
endif()

function(nonsep_write_formula_toolchain file)
  set(quoted_flags "")
  foreach(flag IN LISTS NONSEP_FORMULA_FLAGS)
    list(APPEND quoted_flags "\"${flag}\"")
  endforeach()
  set(quoted_includes "")
  foreach(folder IN LISTS ARGN)
    list(APPEND quoted_includes "\"${folder}\"")
  endforeach()
  list(JOIN quoted_flags ", " flags)
  list(JOIN quoted_includes ", " includes)
  file(WRITE "${file}.new" "{\"compiler\": \"${CMAKE_CXX_COMPILER}\",\n \"flags\": [${flags}],\n"
                           " \"include_directories\": [${includes}]}\n")
  file(COPY_FILE "${file}.new" "${file}" ONLY_IF_DIFFERENT)
  file(REMOVE "${file}.new")
endfunction()

# nlohmann/json.hpp, when it is not in the compiler's own search path.
get_target_property(nonsep_json_includes nlohmann_json::nlohmann_json INTERFACE_INCLUDE_DIRECTORIES)
set(nonsep_formula_extra_includes "")
foreach(folder IN LISTS nonsep_json_includes)
  if(NOT folder IN_LIST CMAKE_CXX_IMPLICIT_INCLUDE_DIRECTORIES)
    list(APPEND nonsep_formula_extra_includes "${folder}")
  endif()
endforeach()

nonsep_write_formula_toolchain("${NONSEP_BUILD_DATADIR}/formula/toolchain.json"
  "${PROJECT_SOURCE_DIR}/plugins/sdk/include" "${PROJECT_SOURCE_DIR}/core/include" ${nonsep_formula_extra_includes})
file(RELATIVE_PATH nonsep_include_from_toolchain "/${NONSEP_INSTALL_DATADIR}/formula" "/${CMAKE_INSTALL_INCLUDEDIR}")
nonsep_write_formula_toolchain("${PROJECT_BINARY_DIR}/install-formula/toolchain.json"
  "${nonsep_include_from_toolchain}" ${nonsep_formula_extra_includes})
install(FILES "${PROJECT_BINARY_DIR}/install-formula/toolchain.json" DESTINATION ${NONSEP_INSTALL_DATADIR}/formula)
