# client/cli/: the `octomap-rt` command-line program. One file per subcommand (*_command.cpp);
# everything but main.cpp is the library octomap_rt_client (also linked by the load test and
# the integration tests); bench/, query/, replay/ and status/ hold the helpers of those subcommands.
file(GLOB CLI_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.cpp ${CMAKE_CURRENT_LIST_DIR}/bench/*.cpp
     ${CMAKE_CURRENT_LIST_DIR}/query/*.cpp ${CMAKE_CURRENT_LIST_DIR}/replay/*.cpp)
list(FILTER CLI_SOURCES EXCLUDE REGEX "/main\\.cpp$")
add_library(octomap_rt_client STATIC ${CLI_SOURCES})
target_include_directories(octomap_rt_client PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
target_link_libraries(octomap_rt_client PUBLIC octomap_rt_engine octomap_rt_scene CLI11::CLI11 octomap_rt_lcmtypes octomap_rt_lcm)
octomap_rt_lcm_handler_sources(octomap_rt_client ${CMAKE_CURRENT_LIST_DIR}/replay/lcm_server_wait.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/status_command.cpp)
include(${CMAKE_CURRENT_LIST_DIR}/status/status.cmake)
target_link_libraries(octomap_rt_client PUBLIC octomap_rt_status octomap_rt_render octomap_rt_query_client
                      octomap_rt_map_client octomap_rt_shard_client)

add_executable(octomap-rt ${CMAKE_CURRENT_LIST_DIR}/main.cpp)
target_compile_definitions(octomap-rt PRIVATE OCTOMAP_RT_VERSION="${PROJECT_VERSION}")
target_link_libraries(octomap-rt PRIVATE octomap_rt_client octomap_rt_allocator octomap_rt_huge_pages)
