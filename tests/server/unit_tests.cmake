# In-process tests of octomap-rt-server's logic over memq:// (no network, no GPU: cpu back end).
set(SERVER_TEST_FIXTURES $<TARGET_OBJECTS:octomap_rt_server_fixtures>)  # tests/CMakeLists.txt
octomap_rt_add_test(server_validation_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/scan_validation_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/scan_decode_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 120)
octomap_rt_add_test(server_memq_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/server_memq_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/server_admission_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/server_status_counts_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/server_published_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/map_request_bounds_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 600)
octomap_rt_lcm_handler_sources(server_memq_test ${CMAKE_CURRENT_LIST_DIR}/server_memq_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/server_published_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/map_request_bounds_test.cpp)
octomap_rt_add_test(server_persistence_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/map_store_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/server_persistence_test.cpp ${CMAKE_CURRENT_LIST_DIR}/map_file_integrity_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/map_identity_test.cpp ${CMAKE_CURRENT_LIST_DIR}/map_replica_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/map_replica_rebuild_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/prior_map_test.cpp
                    ${SERVER_TEST_FIXTURES}
                    LIBS octomap_rt_daemon TIMEOUT 300)
octomap_rt_add_test(lcm_loop_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/lcm_loop_test.cpp LIBS octomap_rt_daemon TIMEOUT 120)
octomap_rt_lcm_handler_sources(lcm_loop_test ${CMAKE_CURRENT_LIST_DIR}/lcm_loop_test.cpp)
# The run summary's slowest scans and what it says about them.
octomap_rt_add_test(server_run_summary_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/run_summary_test.cpp
                    LIBS octomap_rt_daemon TIMEOUT 60)
octomap_rt_add_test(server_producer_registry_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/producer_registry_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/scan_queue_test.cpp ${CMAKE_CURRENT_LIST_DIR}/shared_class_budget_test.cpp
                    LIBS octomap_rt_daemon TIMEOUT 60)
# The rule behind the status' DEGRADED state and its causes.
octomap_rt_add_test(server_degraded_causes_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/degraded_causes_test.cpp
                    LIBS octomap_rt_daemon TIMEOUT 60)
octomap_rt_add_test(server_hardening_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/server_hardening_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/scan_costs_test.cpp ${CMAKE_CURRENT_LIST_DIR}/producer_share_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/shared_budget_server_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 600)
octomap_rt_lcm_handler_sources(server_hardening_test ${CMAKE_CURRENT_LIST_DIR}/scan_costs_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/producer_share_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/shared_budget_server_test.cpp)
octomap_rt_add_test(server_shutdown_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/server_shutdown_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
# The query service (issue 11): answers, read-your-writes, edits, bad queries, over memq://.
octomap_rt_add_test(server_query_service_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/query_service_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/query_edits_test.cpp ${CMAKE_CURRENT_LIST_DIR}/query_bounds_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/query_replica_test.cpp ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon
                    TIMEOUT 300)
octomap_rt_lcm_handler_sources(server_query_service_test ${CMAKE_CURRENT_LIST_DIR}/query_service_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/query_edits_test.cpp ${CMAKE_CURRENT_LIST_DIR}/query_bounds_test.cpp
                               ${CMAKE_CURRENT_LIST_DIR}/query_replica_test.cpp)
# ... its counters in the status and the grid it publishes at a rate (issue 11).
octomap_rt_add_test(server_query_status_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/query_status_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 120)
# Map deltas from the octree stage's change log against OctoMap's search() and the old
# look-up path, on the real data sets (issue 12).
octomap_rt_add_test(server_delta_changes_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/delta_changes_test.cpp
                    LIBS octomap_rt_daemon TIMEOUT 600)
# The long-lived map's upkeep in the daemon: decay steps and clearing passes between scans.
octomap_rt_add_test(map_upkeep_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/map_upkeep_test.cpp ${SERVER_TEST_FIXTURES}
                    LIBS octomap_rt_daemon TIMEOUT 120)
# The memory bound in the daemon: real scans past --max-map-memory, saves, restarts, kill -9.
octomap_rt_add_test(memory_bound_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/memory_bound_test.cpp ${SERVER_TEST_FIXTURES}
                    LIBS octomap_rt_daemon TIMEOUT 300)
octomap_rt_lcm_handler_sources(memory_bound_test ${CMAKE_CURRENT_LIST_DIR}/memory_bound_test.cpp)
# The memory bound with two robots over memq://: the map with eviction is OctoMap's, whatever the working set.
octomap_rt_add_test(memory_bound_robots_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/memory_bound_robots_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
# The memory bound's edges: the map's memory right after a scan's restores, a .bt prior past the bound.
octomap_rt_add_test(map_residency_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/map_residency_test.cpp ${SERVER_TEST_FIXTURES}
                    $<TARGET_OBJECTS:octomap_rt_octree_test_helpers> LIBS octomap_rt_daemon TIMEOUT 120)
# Issue 21: every numeric field of scan_t at its degenerate values, on every back end.
octomap_rt_add_test(server_scan_fields_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/scan_fields_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
# Issue 21: the server's numeric flags are range-checked at start.
octomap_rt_add_test(server_flags_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/server_flags_test.cpp TIMEOUT 120)
target_compile_definitions(server_flags_test PRIVATE OCTOMAP_RT_SERVER="$<TARGET_FILE:octomap-rt-server>")
add_dependencies(server_flags_test octomap-rt-server)
# Issue 24: an organised cloud with NaN no-returns (a range image of a real scan), every back end.
octomap_rt_add_test(server_organised_cloud_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/organised_cloud_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
# The memory bound's region store: crash-safe puts (kill -9), lock, bound, full disk.
octomap_rt_add_test(region_store_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/region_store_test.cpp ${SERVER_TEST_FIXTURES}
                    LIBS octomap_rt_daemon TIMEOUT 120)
# Issue 24: octomap_server's filters (map-frame and sensor-frame pass-through, min range) against OctoMap.
octomap_rt_add_test(server_point_filters_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/point_filters_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
# The server's command line: --namespace, --config's unknown keys, --print-config (issue 24).
octomap_rt_add_test(server_cli_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/server_cli_test.cpp
                    LIBS octomap_rt_server_cli TIMEOUT 60)
# Issue 26: shards keep their regions' voxels; merged they are the one-daemon map (real data).
octomap_rt_add_test(server_shard_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/shard_test.cpp ${SERVER_TEST_FIXTURES}
                    LIBS octomap_rt_daemon octomap_rt_map_client TIMEOUT 300)
# Distance queries (issue 27): points, boxes and paths through the daemon, CPU and Vulkan EDT.
octomap_rt_add_test(server_distance_query_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/distance_query_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
octomap_rt_lcm_handler_sources(server_distance_query_test ${CMAKE_CURRENT_LIST_DIR}/distance_query_test.cpp)
# Issue 26: rays across shards (each stopping in its own regions), merged, equal one daemon's castRay.
octomap_rt_add_test(server_shard_ray_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/shard_ray_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon octomap_rt_shard_client TIMEOUT 120)
# Issues 26 + 27: distances across shards, merged as the shard client merges them, equal one daemon's.
octomap_rt_add_test(server_shard_distance_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/shard_distance_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon octomap_rt_shard_client TIMEOUT 120)
# Issue 27: a distance box's blob by z-slabs, the unchanged slabs' frames kept (real data).
octomap_rt_add_test(server_box_frames_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/box_frames_test.cpp
                    $<TARGET_OBJECTS:octomap_rt_query_test_maps> LIBS octomap_rt_daemon TIMEOUT 120)
set_property(TEST server_box_frames_test APPEND PROPERTY LABELS data)
# Issue 27: the distance field cache kept from the map's change lists while a robot explores (real data).
octomap_rt_add_test(server_distance_journal_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/distance_journal_test.cpp
                    ${SERVER_TEST_FIXTURES} LIBS octomap_rt_daemon TIMEOUT 300)
