# rt back end (issue 5): the GPU-free parts on the CPU; the GPU parity test skips cleanly
# where the device lacks the ray-tracing extensions (lavapipe).
octomap_rt_add_test(gpu_rt_space_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/rt_space_test.cpp TIMEOUT 300)
