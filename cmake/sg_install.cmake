# `cmake --install`: headers, the static libraries sg::<layer>, the stereoguard binary, and a
# stereoguardConfig.cmake (+ version file) so that find_package(stereoguard) works.
include(CMakePackageConfigHelpers)

set(SG_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/stereoguard)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/sg DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT stereoguardTargets NAMESPACE sg:: DESTINATION ${SG_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/stereoguardConfig.cmake.in
  ${PROJECT_BINARY_DIR}/stereoguardConfig.cmake INSTALL_DESTINATION ${SG_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/stereoguardConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/stereoguardConfig.cmake
              ${PROJECT_BINARY_DIR}/stereoguardConfigVersion.cmake
        DESTINATION ${SG_INSTALL_CMAKEDIR})
