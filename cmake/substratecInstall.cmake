# Installation and the CMake package (find_package(substratec)): the compiler,
# the runtime shaders and schemas it generates code against, and the package
# files (substratecConfig.cmake, its version file, SubstratecMaterials.cmake).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(SUBSTRATEC_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/substratec")
set(SUBSTRATEC_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/substratec")

install(TARGETS substratec RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/runtime_shaders/ DESTINATION ${SUBSTRATEC_INSTALL_DATADIR}/runtime_shaders)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/schema/ DESTINATION ${SUBSTRATEC_INSTALL_DATADIR}/schema
        FILES_MATCHING PATTERN "*.json")

configure_package_config_file(
  ${PROJECT_SOURCE_DIR}/cmake/substratecConfig.cmake.in ${PROJECT_BINARY_DIR}/cmake/substratecConfig.cmake
  INSTALL_DESTINATION ${SUBSTRATEC_INSTALL_CMAKEDIR}
  PATH_VARS CMAKE_INSTALL_BINDIR SUBSTRATEC_INSTALL_DATADIR)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/substratecConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/substratecConfig.cmake ${PROJECT_BINARY_DIR}/cmake/substratecConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/SubstratecMaterials.cmake
        DESTINATION ${SUBSTRATEC_INSTALL_CMAKEDIR})
