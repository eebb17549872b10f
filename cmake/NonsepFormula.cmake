# Formula models (docs/formula-models.md): the host compiles them on first use with the compiler and flags of this
# build, described in share/nonsep/formula/toolchain.json, installed and in the build tree (NonsepShare.cmake):
#   {"compiler": "/usr/bin/c++", "flags": [...], "include_directories": [...], "libraries": [...]}
# Include folders and libraries (the SDK's, libnonsep_sdk.a: plugins/CMakeLists.txt) are relative to the file's own
# folder (installed: <prefix>/include, <prefix>/lib) or absolute (build tree: the SDK and core headers of the sources,
# the library this build made). The flags are those of a Release plugin (nonsep_add_model), never the
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

# nonsep_write_formula_toolchain(<file> LIBRARIES <paths>... INCLUDES <folders>...): written at generation time
# (file(GENERATE): a library may be a generator expression), and only when its content changes.
function(nonsep_write_formula_toolchain file)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "LIBRARIES;INCLUDES")
  set(quoted_flags "")
  foreach(flag IN LISTS NONSEP_FORMULA_FLAGS)
    list(APPEND quoted_flags "\"${flag}\"")
  endforeach()
  set(quoted_includes "")
  foreach(folder IN LISTS arg_INCLUDES)
    list(APPEND quoted_includes "\"${folder}\"")
  endforeach()
  set(quoted_libraries "")
  foreach(library IN LISTS arg_LIBRARIES)
    list(APPEND quoted_libraries "\"${library}\"")
  endforeach()
  list(JOIN quoted_flags ", " flags)
  list(JOIN quoted_includes ", " includes)
  list(JOIN quoted_libraries ", " libraries)
  string(CONCAT content "{\"compiler\": \"${CMAKE_CXX_COMPILER}\",\n \"flags\": [${flags}],\n"
                        " \"include_directories\": [${includes}],\n \"libraries\": [${libraries}]}\n")
  file(GENERATE OUTPUT "${file}" CONTENT "${content}")
endfunction()

nonsep_write_formula_toolchain("${NONSEP_BUILD_DATADIR}/formula/toolchain.json"
  LIBRARIES "$<TARGET_FILE:nonsep_sdk>"
  INCLUDES "${PROJECT_SOURCE_DIR}/plugins/sdk/include" "${PROJECT_SOURCE_DIR}/core/include")
file(RELATIVE_PATH nonsep_include_from_toolchain "/${NONSEP_INSTALL_DATADIR}/formula" "/${CMAKE_INSTALL_INCLUDEDIR}")
file(RELATIVE_PATH nonsep_lib_from_toolchain "/${NONSEP_INSTALL_DATADIR}/formula" "/${CMAKE_INSTALL_LIBDIR}")
nonsep_write_formula_toolchain("${PROJECT_BINARY_DIR}/install-formula/toolchain.json"
  LIBRARIES "${nonsep_lib_from_toolchain}/$<TARGET_FILE_NAME:nonsep_sdk>"
  INCLUDES "${nonsep_include_from_toolchain}")
install(FILES "${PROJECT_BINARY_DIR}/install-formula/toolchain.json" DESTINATION ${NONSEP_INSTALL_DATADIR}/formula)
