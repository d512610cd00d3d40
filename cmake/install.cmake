# `cmake --install`: the programs, the map client library with its headers, the generated
# C++ types, and a CMake package config so that a planner's project does
#   find_package(octomap_rt REQUIRED)
#   target_link_libraries(planner PRIVATE octomap_rt::map_client)      # and/or
#   target_link_libraries(planner PRIVATE octomap_rt::query_client)    # "query_client/client.h"
# (The Java jar and the Python package install themselves: lcmtypes/, client/bindings/python/.)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)
set(ORT_INCLUDE_DEST ${CMAKE_INSTALL_INCLUDEDIR}/octomap_rt)
set(ORT_CMAKE_DEST ${CMAKE_INSTALL_LIBDIR}/cmake/octomap_rt)

install(TARGETS octomap-rt-server octomap-rt RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
set_target_properties(octomap_rt_protocol PROPERTIES EXPORT_NAME protocol)
set_target_properties(octomap_rt_lcmtypes PROPERTIES EXPORT_NAME lcmtypes)
set_target_properties(octomap_rt_lcm PROPERTIES EXPORT_NAME lcm)
set_target_properties(octomap_rt_octomap PROPERTIES EXPORT_NAME octomap)
set_target_properties(octomap_rt_clock PROPERTIES EXPORT_NAME clock)
install(TARGETS octomap_rt_map_client octomap_rt_query_client octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_lcm octomap_rt_octomap
        octomap_rt_clock EXPORT octomap_rtTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${ORT_INCLUDE_DEST})
install(DIRECTORY ${CMAKE_SOURCE_DIR}/client/map_client/ DESTINATION ${ORT_INCLUDE_DEST}/map_client
        FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${CMAKE_SOURCE_DIR}/client/query_client/ DESTINATION ${ORT_INCLUDE_DEST}/query_client
        FILES_MATCHING PATTERN "*.h")
install(DIRECTORY ${CMAKE_SOURCE_DIR}/protocol/ DESTINATION ${ORT_INCLUDE_DEST}/protocol FILES_MATCHING PATTERN "*.h")
install(FILES ${CMAKE_SOURCE_DIR}/server/core/clock.h DESTINATION ${ORT_INCLUDE_DEST}/core)
install(DIRECTORY ${CMAKE_BINARY_DIR}/lcmtypes/cpp/ DESTINATION ${ORT_INCLUDE_DEST} FILES_MATCHING PATTERN "*.hpp")
install(EXPORT octomap_rtTargets NAMESPACE octomap_rt:: DESTINATION ${ORT_CMAKE_DEST})
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/octomap_rtConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/octomap_rtConfig.cmake INSTALL_DESTINATION ${ORT_CMAKE_DEST})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/octomap_rtConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/octomap_rtConfig.cmake ${CMAKE_BINARY_DIR}/octomap_rtConfigVersion.cmake
        DESTINATION ${ORT_CMAKE_DEST})
