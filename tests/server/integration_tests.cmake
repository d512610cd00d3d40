# Integration tests of octomap-rt-server with real processes (daemon, `octomap-rt replay`
# producers, lcm-logger) talking udpm inside a network namespace each test makes itself.
# Included from tests.cmake. Label: integration.
set(ORT_IT_DIR ${CMAKE_CURRENT_LIST_DIR})
add_library(octomap_rt_integration_harness STATIC ${CMAKE_CURRENT_LIST_DIR}/integration_harness.cpp)
target_include_directories(octomap_rt_integration_harness PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(octomap_rt_integration_harness PUBLIC octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_test_support GTest::gtest)
octomap_rt_lcm_handler_sources(octomap_rt_integration_harness ${CMAKE_CURRENT_LIST_DIR}/integration_harness.cpp)
target_compile_definitions(octomap_rt_integration_harness PRIVATE
  OCTOMAP_RT_SERVER="$<TARGET_FILE:octomap-rt-server>" OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")

function(octomap_rt_add_integration_test name timeout)
  octomap_rt_add_test(${name} SOURCES ${ORT_IT_DIR}/${name}.cpp
                      LIBS octomap_rt_integration_harness octomap_rt_client octomap_rt_map_client octomap_rt_daemon
                      TIMEOUT ${timeout} LABELS integration)
  add_dependencies(${name} octomap-rt-server octomap-rt)
endfunction()

octomap_rt_add_integration_test(server_producers_integration_test 300)
octomap_rt_add_integration_test(server_large_scans_integration_test 400)
octomap_rt_add_integration_test(server_persistence_integration_test 400)
octomap_rt_add_integration_test(server_log_replay_integration_test 400)
octomap_rt_add_integration_test(map_serving_integration_test 600)
# Installs this build into a temporary prefix and builds client/examples/map_fetch against it.
octomap_rt_add_integration_test(install_integration_test 900)
target_compile_definitions(install_integration_test PRIVATE OCTOMAP_RT_BUILD_DIR="${CMAKE_BINARY_DIR}"
                           OCTOMAP_RT_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
# Read-your-writes: a robot's query right after its scan sees that scan (issue 11).
octomap_rt_add_integration_test(query_integration_test 300)
target_link_libraries(query_integration_test PRIVATE octomap_rt_query_client)
octomap_rt_add_integration_test(server_signals_integration_test 300)
octomap_rt_add_integration_test(map_identity_integration_test 300)
# Issue 26: three shards in one namespace; the CLI merges their maps, queries routed by region.
octomap_rt_add_integration_test(shards_integration_test 300)
target_link_libraries(shards_integration_test PRIVATE octomap_rt_shard_client)
# Every shard's deltas in one mirror: it equals the merged snapshot; one shard's new epoch; late, missing.
octomap_rt_add_integration_test(shard_mirror_integration_test 300)
target_link_libraries(shard_mirror_integration_test PRIVATE octomap_rt_shard_client)
