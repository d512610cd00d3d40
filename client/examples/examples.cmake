# client/examples/: planners on the client libraries. grid_planner.cpp (octomap-rt-plan) is
# built by default and installed; map_fetch/ and query_point/ are programs' own projects against
# the installed libraries (built out of tree by install_integration_test).
add_executable(octomap-rt-plan ${CMAKE_CURRENT_LIST_DIR}/grid_planner.cpp)
target_link_libraries(octomap-rt-plan PRIVATE octomap_rt_client)
target_compile_definitions(octomap-rt-plan PRIVATE OCTOMAP_RT_VERSION="${PROJECT_VERSION}")
install(TARGETS octomap-rt-plan RUNTIME DESTINATION bin)

# The C++ producer of README's "Connect your robot" (publish_scan.cpp): built by default, run by
# tests/python/test_producers.py against a real server.
add_executable(octomap-rt-publish-example ${CMAKE_CURRENT_LIST_DIR}/publish_scan.cpp)
target_link_libraries(octomap-rt-publish-example PRIVATE octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_lcm octomap_rt_octomap)
