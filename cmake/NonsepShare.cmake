# The user's files that are not code: the manual (README.md, which `nonsep --help` names), docs/, the job schema
# and the example job files (examples/{jobs,paper,dynamics}/*.json, which `nonsep example` writes out).
# Installed under <prefix>/share/nonsep/; mirrored in the build tree's share/nonsep/ by symbolic links to the
# sources, so that the host finds them relative to its executable (bin/../share/nonsep) in both, with no path of
# this machine compiled in, and the build tree always shows the current sources.
#
#   share/nonsep/README.md
#   share/nonsep/docs/...
#   share/nonsep/schemas/job.schema.json        (the examples' "$schema": "../../schemas/job.schema.json" resolves)
#   share/nonsep/examples/jobs/*.json
#   share/nonsep/examples/paper/*.json
#   share/nonsep/examples/dynamics/*.json
set(NONSEP_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/nonsep" CACHE STRING
  "Folder of the manual, schema and example jobs, relative to the install prefix")
if(IS_ABSOLUTE "${NONSEP_INSTALL_DATADIR}")
  message(FATAL_ERROR "NONSEP_INSTALL_DATADIR must be relative to the install prefix (found ${NONSEP_INSTALL_DATADIR}): "
                      "the host finds it relative to its executable")
endif()
set(NONSEP_BUILD_DATADIR "${PROJECT_BINARY_DIR}/${NONSEP_INSTALL_DATADIR}")

install(FILES README.md DESTINATION ${NONSEP_INSTALL_DATADIR})
install(DIRECTORY docs/ DESTINATION ${NONSEP_INSTALL_DATADIR}/docs)
install(FILES schemas/job.schema.json DESTINATION ${NONSEP_INSTALL_DATADIR}/schemas)
foreach(folder jobs paper dynamics)
  # Only the job files at the top of each folder: not the outputs (<job>.out/) of jobs run in the source tree.
  file(GLOB example_jobs CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/examples/${folder}/*.json")
  install(FILES ${example_jobs} DESTINATION ${NONSEP_INSTALL_DATADIR}/examples/${folder})
endforeach()

file(MAKE_DIRECTORY "${NONSEP_BUILD_DATADIR}/examples")
foreach(item README.md docs schemas examples/jobs examples/paper examples/dynamics)
  if(IS_SYMLINK "${NONSEP_BUILD_DATADIR}/${item}")
    file(REMOVE "${NONSEP_BUILD_DATADIR}/${item}")
  endif()
  file(CREATE_LINK "${PROJECT_SOURCE_DIR}/${item}" "${NONSEP_BUILD_DATADIR}/${item}" SYMBOLIC)
endforeach()
