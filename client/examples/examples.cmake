# client/examples/: planners on the client libraries. grid_planner.cpp (octomap-rt-plan) is
# built by default and installed; map_fetch/ is a planner's own project against the installed
# library (built out of tree by install_integration_test).
add_executable(octomap-rt-plan ${CMAKE_CURRENT_LIST_DIR}/grid_planner.cpp)
target_link_libraries(octomap-rt-plan PRIVATE octomap_rt_client)
install(TARGETS octomap-rt-plan RUNTIME DESTINATION bin)
