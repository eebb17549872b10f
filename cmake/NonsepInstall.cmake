# Installation: headers, libraries, the host, shipped plugins and the CMake package `nonsep`
# (find_package(nonsep) provides nonsep::core, nonsep::sdk and nonsep_add_model()).
include(CMakePackageConfigHelpers)

set(NONSEP_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/nonsep")

install(DIRECTORY core/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS nonsep_core EXPORT nonsepTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})

install(EXPORT nonsepTargets NAMESPACE nonsep:: DESTINATION ${NONSEP_INSTALL_CMAKEDIR})
configure_package_config_file(cmake/nonsepConfig.cmake.in "${PROJECT_BINARY_DIR}/nonsepConfig.cmake"
  INSTALL_DESTINATION ${NONSEP_INSTALL_CMAKEDIR})
write_basic_package_version_file("${PROJECT_BINARY_DIR}/nonsepConfigVersion.cmake" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/nonsepConfig.cmake" "${PROJECT_BINARY_DIR}/nonsepConfigVersion.cmake"
  DESTINATION ${NONSEP_INSTALL_CMAKEDIR})
