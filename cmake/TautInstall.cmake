# Installable CMake package: find_package(taut) then target_link_libraries(app taut::taut).
include(CMakePackageConfigHelpers)
install(TARGETS taut taut_bullet_bridge taut_constraints taut_plugin
        EXPORT tautTargets
        ARCHIVE DESTINATION lib
        LIBRARY DESTINATION lib
        RUNTIME DESTINATION bin)
install(EXPORT tautTargets NAMESPACE taut:: DESTINATION lib/cmake/taut)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tautConfig.cmake.in
  ${PROJECT_BINARY_DIR}/tautConfig.cmake INSTALL_DESTINATION lib/cmake/taut)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tautConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/tautConfig.cmake ${PROJECT_BINARY_DIR}/tautConfigVersion.cmake
        DESTINATION lib/cmake/taut)
