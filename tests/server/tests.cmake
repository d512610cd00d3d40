include(${CMAKE_CURRENT_LIST_DIR}/integration_tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/unit_tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/viewer_tests.cmake)

set_property(TEST server_memq_test server_delta_changes_test install_integration_test map_serving_integration_test
             query_integration_test server_log_replay_integration_test server_persistence_integration_test
             server_producers_integration_test region_store_test memory_bound_test memory_bound_robots_test
             map_residency_test server_distance_journal_test APPEND PROPERTY LABELS data)
set_property(TEST server_memq_test server_hardening_test server_delta_changes_test APPEND PROPERTY LABELS slow)
