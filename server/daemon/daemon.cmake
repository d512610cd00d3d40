# octomap-rt-server: the LCM mapping daemon (included by server/CMakeLists.txt).
# The daemon's logic is a library (octomap_rt_daemon) so tests run it in-process over
# memq://; the executable adds only flag parsing, signals and the summary.
set(DAEMON_DIR ${CMAKE_CURRENT_LIST_DIR})
file(GLOB_RECURSE DAEMON_SOURCES CONFIGURE_DEPENDS ${DAEMON_DIR}/*.cpp)
list(FILTER DAEMON_SOURCES EXCLUDE REGEX "/(server_main|server_cli|server_flag_groups)\\.cpp$")
add_library(octomap_rt_daemon STATIC ${DAEMON_SOURCES})
target_include_directories(octomap_rt_daemon PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(octomap_rt_daemon PUBLIC octomap_rt_engine octomap_rt_protocol octomap_rt_query octomap_rt_distance octomap_rt_lcmtypes octomap_rt_lcm Threads::Threads)
octomap_rt_lcm_handler_sources(octomap_rt_daemon ${DAEMON_DIR}/transport/lcm_loop.cpp)

# The engine flags (-r, sensor model, back end, ...) come from engine/engine_flags, shared so
# that `octomap-rt build` and the server take the same names and defaults.
# The server's command line, a library of its own so that its tests and the benches that start
# a daemon with the server's flags compile it once.
add_library(octomap_rt_server_cli STATIC ${DAEMON_DIR}/server_cli.cpp ${DAEMON_DIR}/server_flag_groups.cpp)
target_link_libraries(octomap_rt_server_cli PUBLIC octomap_rt_daemon)
add_executable(octomap-rt-server ${DAEMON_DIR}/server_main.cpp)
target_link_libraries(octomap-rt-server PRIVATE octomap_rt_server_cli octomap_rt_allocator)
target_compile_definitions(octomap-rt-server PRIVATE OCTOMAP_RT_VERSION="${PROJECT_VERSION}")
