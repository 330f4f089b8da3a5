# `cmake --install build --prefix P`: the libraries and their headers (P/include/metriplex,
# included as "engine/...", "models/...", "tools/..."), the exported package
# P/lib/cmake/Metriplex, the metriplex program, the scene format and example scenes.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# one target for users: Metriplex::metriplex
add_library(metriplex_library INTERFACE)
set_target_properties(metriplex_library PROPERTIES EXPORT_NAME metriplex)
target_link_libraries(metriplex_library INTERFACE metriplex_session)
add_library(Metriplex::metriplex ALIAS metriplex_library)

install(TARGETS metriplex_library metriplex_session metriplex_output metriplex_scene metriplex_models
                metriplex_engine
        EXPORT MetriplexTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS metriplex RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY engine models tools DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/metriplex
        FILES_MATCHING PATTERN "*.hpp" PATTERN "commands.hpp" EXCLUDE)
install(EXPORT MetriplexTargets NAMESPACE Metriplex:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Metriplex)
configure_package_config_file(cmake/MetriplexConfig.cmake.in ${CMAKE_BINARY_DIR}/MetriplexConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Metriplex)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/MetriplexConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/MetriplexConfig.cmake ${CMAKE_BINARY_DIR}/MetriplexConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/Metriplex)
install(FILES docs/scene-format.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY scenes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/metriplex/scenes)
