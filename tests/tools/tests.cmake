# tools/: the scene generator (geometry, sensors, presets) and the `octomap-rt bench` smoke test.
octomap_rt_add_test(tools_scene_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/scene_test.cpp TIMEOUT 300)

octomap_rt_add_test(tools_bench_smoke_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/bench_smoke_test.cpp TIMEOUT 600)
target_compile_definitions(tools_bench_smoke_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(tools_bench_smoke_test octomap-rt)

# Hostile and unlucky command-line input (issue 13): broken .graph files, full disks, NaN flags.
octomap_rt_add_test(tools_cli_input_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/cli_input_test.cpp
                    ${CMAKE_SOURCE_DIR}/client/cli/octomap_chatter.cpp TIMEOUT 300)
target_compile_definitions(tools_cli_input_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(tools_cli_input_test octomap-rt)

# The load test tool, short (issue 13): N producers in a network namespace, status decoded.
octomap_rt_add_test(tools_load_test_smoke_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/load_test_smoke_test.cpp TIMEOUT 300
                    LABELS integration)
target_compile_definitions(tools_load_test_smoke_test PRIVATE OCTOMAP_RT_LOADTEST="$<TARGET_FILE:octomap-rt-loadtest>")
add_dependencies(tools_load_test_smoke_test octomap-rt-loadtest)

set_property(TEST tools_cli_input_test tools_scene_test APPEND PROPERTY LABELS data)
set_property(TEST tools_bench_smoke_test APPEND PROPERTY LABELS slow)
