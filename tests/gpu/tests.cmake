# GPU back-end tests (vulkan compute). They run on whatever Vulkan device is found:
# lavapipe in CI; $OCTOMAP_RT_TEST_DEVICE picks one (index or name substring).
set(GPU_TEST_DIR ${CMAKE_CURRENT_LIST_DIR})
add_library(octomap_rt_gpu_test_support STATIC ${GPU_TEST_DIR}/gpu_test_support.cpp ${GPU_TEST_DIR}/random_rays.cpp)
target_include_directories(octomap_rt_gpu_test_support PUBLIC ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(octomap_rt_gpu_test_support PUBLIC octomap_rt_test_support)

octomap_rt_add_test(gpu_traversal_test SOURCES ${GPU_TEST_DIR}/traversal_test.cpp
                    LIBS octomap_rt_gpu_test_support TIMEOUT 600)

# rt back end (issue 5): the GPU-free parts on the CPU (layout, windows, window frame, a CPU
# model of the rt shoot against the exact reference).
octomap_rt_add_test(gpu_rt_block_grid_test SOURCES ${GPU_TEST_DIR}/rt_block_grid_test.cpp TIMEOUT 300)
# rt against vulkan and the exact reference on the GPU; on a device without ray tracing it
# checks the clean refusal and skips the comparisons.
octomap_rt_add_test(gpu_rt_parity_test SOURCES ${GPU_TEST_DIR}/rt_parity_test.cpp
                    LIBS octomap_rt_gpu_test_support TIMEOUT 900)
octomap_rt_add_test(gpu_ray_space_test SOURCES ${GPU_TEST_DIR}/ray_space_test.cpp
                    LIBS octomap_rt_gpu_test_support TIMEOUT 600)
octomap_rt_add_test(gpu_device_test SOURCES ${GPU_TEST_DIR}/device_choice_test.cpp TIMEOUT 300)
octomap_rt_add_test(gpu_no_device_test SOURCES ${GPU_TEST_DIR}/no_device_test.cpp TIMEOUT 120)
# `octomap-rt build --backend rt`: builds, or refuses cleanly without ray tracing.
octomap_rt_add_test(gpu_rt_cli_test SOURCES ${GPU_TEST_DIR}/rt_cli_test.cpp TIMEOUT 300)
target_compile_definitions(gpu_rt_cli_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(gpu_rt_cli_test octomap-rt)

# GPU scan preparation (issue 12) against the CPU's, bit for bit.
octomap_rt_add_test(gpu_prepare_test SOURCES ${GPU_TEST_DIR}/gpu_prepare_test.cpp
                    LIBS octomap_rt_gpu_test_support TIMEOUT 600)

# The Vulkan distance transform (issue 27) against the CPU one, bit for bit.
octomap_rt_add_test(gpu_distance_test SOURCES ${GPU_TEST_DIR}/gpu_distance_test.cpp
                    $<TARGET_OBJECTS:octomap_rt_query_test_maps>
                    LIBS octomap_rt_gpu octomap_rt_distance TIMEOUT 600)

set_property(TEST gpu_prepare_test gpu_rt_parity_test gpu_distance_test APPEND PROPERTY LABELS data)
set_property(TEST gpu_traversal_test gpu_rt_parity_test gpu_ray_space_test gpu_prepare_test gpu_distance_test
             APPEND PROPERTY LABELS slow)
