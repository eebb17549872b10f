# Installation: headers, libraries, the host, shipped plugins and the CMake package `nonsep`
# (find_package(nonsep) provides nonsep::core, nonsep::sdk, nonsep::loader and nonsep_add_model()).
#
# Layout under the prefix:
#   include/nonsep/...                  core, SDK (plugin_abi.h, plugin_sdk.hpp, derivative_checker.hpp), loader
#   lib/libnonsep_core.a, lib/libnonsep_loader.a  (for programs that integrate or load plugins; a plugin links
#                                                  neither)
#   lib/libnonsep_sdk.a                 the SDK's JSON reading and writing, which every plugin links (nonsep::sdk)
#   lib/nonsep/plugins/<name>.so        shipped models (NONSEP_INSTALL_PLUGINDIR; the host finds it from bin/)
#   lib/cmake/nonsep/                   nonsepConfig.cmake, targets, NonsepAddModel.cmake
include(CMakePackageConfigHelpers)

set(NONSEP_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/nonsep")

install(DIRECTORY core/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(nonsep_exported_targets nonsep_core)
if(TARGET nonsep_sdk)
  install(DIRECTORY plugins/sdk/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  list(APPEND nonsep_exported_targets nonsep_sdk)
  install(TARGETS ${NONSEP_SHIPPED_MODELS} LIBRARY DESTINATION ${NONSEP_INSTALL_PLUGINDIR})
endif()
if(TARGET nonsep_loader)
  install(DIRECTORY host/loader/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  list(APPEND nonsep_exported_targets nonsep_loader)
endif()
install(TARGETS ${nonsep_exported_targets} EXPORT nonsepTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})

install(EXPORT nonsepTargets NAMESPACE nonsep:: DESTINATION ${NONSEP_INSTALL_CMAKEDIR})
# The installed config is generated into a folder find_package does not search (install-config/, not nonsep*/):
# the build tree is no package, and a user who gives it as CMAKE_PREFIX_PATH finds nonsepConfig-build-tree.cmake
# instead, which refuses with a message that says to install first (the installed config, found there, failed on
# the missing PREFIX/lib/nonsep/plugins with "//lib/nonsep/plugins ... does not exist").
configure_package_config_file(cmake/nonsepConfig.cmake.in "${PROJECT_BINARY_DIR}/install-config/nonsepConfig.cmake"
  INSTALL_DESTINATION ${NONSEP_INSTALL_CMAKEDIR}
  PATH_VARS NONSEP_INSTALL_PLUGINDIR)
configure_file(cmake/nonsepConfig-build-tree.cmake.in "${PROJECT_BINARY_DIR}/nonsepConfig.cmake" @ONLY)
# SameMajorVersion: find_package(nonsep 0.1) accepts any later 0.x. What a plugin must match is the plugin ABI,
# which the host checks at load time ("expected 3, found 2", with the advice to rebuild), so the CMake package
# need not refuse a newer minor version; a new major version is where the C++ API (core, loader) may break.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/nonsepConfigVersion.cmake" COMPATIBILITY SameMajorVersion)
install(FILES
  "${PROJECT_BINARY_DIR}/install-config/nonsepConfig.cmake"
  "${PROJECT_BINARY_DIR}/nonsepConfigVersion.cmake"
  cmake/NonsepAddModel.cmake
  DESTINATION ${NONSEP_INSTALL_CMAKEDIR})
