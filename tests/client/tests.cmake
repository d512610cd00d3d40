# client/: map pictures (`octomap-rt render`).
octomap_rt_add_test(client_render_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/render_test.cpp
                    LIBS octomap_rt_render TIMEOUT 120)
target_compile_definitions(client_render_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(client_render_test octomap-rt)
