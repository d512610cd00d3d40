# client/: map pictures (`octomap-rt render`).
octomap_rt_add_test(client_render_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/render_test.cpp
                    LIBS octomap_rt_render TIMEOUT 120)
target_compile_definitions(client_render_test PRIVATE OCTOMAP_RT_CLI="$<TARGET_FILE:octomap-rt>")
add_dependencies(client_render_test octomap-rt)

# `octomap-rt status`: layout and JSON (unit), and against a real server in a network namespace.
octomap_rt_add_test(client_status_text_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/status_text_test.cpp
                    LIBS octomap_rt_status TIMEOUT 60)
octomap_rt_add_test(client_status_integration_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/status_integration_test.cpp
                    LIBS octomap_rt_integration_harness TIMEOUT 300 LABELS integration)
add_dependencies(client_status_integration_test octomap-rt-server octomap-rt)
# The Java example (client/bindings/java/) against the same server, when a JDK built it.
if(TARGET octomap_rt_java_examples)
  target_compile_definitions(client_status_integration_test PRIVATE OCTOMAP_RT_JAVA_EXAMPLE_CP="${LCM_JAR}:$<TARGET_PROPERTY:octomap_rt_lcmtypes_jar,JAR_FILE>:$<TARGET_PROPERTY:octomap_rt_java_examples,JAR_FILE>")
  add_dependencies(client_status_integration_test octomap_rt_java_examples)
endif()
