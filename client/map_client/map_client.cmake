# The map client library (snapshots, info, deltas, MapMirror): used by `octomap-rt map`,
# the tests and, installed, by planners' own programs (find_package(octomap_rt)).
file(GLOB MAP_CLIENT_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.cpp)
add_library(octomap_rt_map_client STATIC ${MAP_CLIENT_SOURCES})
set_target_properties(octomap_rt_map_client PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME map_client)
target_include_directories(octomap_rt_map_client PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}>
                           $<INSTALL_INTERFACE:include/octomap_rt>)
target_link_libraries(octomap_rt_map_client PUBLIC octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_lcm
                      octomap_rt_octomap)
add_library(octomap_rt::map_client ALIAS octomap_rt_map_client)
octomap_rt_lcm_handler_sources(octomap_rt_map_client ${CMAKE_CURRENT_LIST_DIR}/map_client.cpp)
