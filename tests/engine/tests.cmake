octomap_rt_add_test(engine_cli_parity_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/cli_parity_test.cpp)
target_compile_definitions(engine_cli_parity_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(engine_cli_parity_test octomap-rt)

octomap_rt_add_test(engine_prepare_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/prepare_scan_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/map_frame_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/exact_traversal_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/ground_helpers_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/periodic_thread_test.cpp)

octomap_rt_add_test(engine_ray_walk_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/ray_walk_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/cpu_grid_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/walk_thread_choice_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/window_walk_stays_test.cpp)

# Issue 13: far-flung scans (path-following tiles, bounded work, OctoMap's map).
octomap_rt_add_test(engine_far_flung_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/far_flung_test.cpp TIMEOUT 600)

# Issue 12: the two-stage pipeline of `octomap-rt bench` / `build` gives the sequential map.
octomap_rt_add_test(engine_pipeline_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/pipeline_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/warm_up_test.cpp TIMEOUT 600)

# Issue 21: rays OctoMap's walk cannot take (degenerate but finite fields) on every back end.
octomap_rt_add_test(engine_degenerate_rays_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/degenerate_rays_test.cpp)

set_property(TEST engine_cli_parity_test engine_pipeline_test APPEND PROPERTY LABELS data)
set_property(TEST engine_far_flung_test engine_pipeline_test APPEND PROPERTY LABELS slow)
