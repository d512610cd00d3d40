# tools/: the scene generator (geometry, sensors, presets) and the `octomap-rt bench` smoke test.
octomap_rt_add_test(tools_scene_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/scene_test.cpp TIMEOUT 300)

octomap_rt_add_test(tools_bench_smoke_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/bench_smoke_test.cpp TIMEOUT 600)
target_compile_definitions(tools_bench_smoke_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(tools_bench_smoke_test octomap-rt)
