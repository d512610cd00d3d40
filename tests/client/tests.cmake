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
# The Java example's MAC of a map edit (javax.crypto) is docs/PROTOCOL.md's test vector.
if(TARGET octomap_rt_java_examples)
  add_test(NAME java_edit_mac_test
           COMMAND ${Java_JAVA_EXECUTABLE} -cp "${LCM_JAR}:$<TARGET_PROPERTY:octomap_rt_lcmtypes_jar,JAR_FILE>:$<TARGET_PROPERTY:octomap_rt_java_examples,JAR_FILE>"
                   MapEdit --mac-of "correct horse battery staple" 1700000000000000 42 81985529216486895 1 1
                   -1.5 -2 0 3.25 4 2.5 op-laptop OCTOMAP_RT_QUERY_REPLY_op-laptop)
  set_tests_properties(java_edit_mac_test PROPERTIES TIMEOUT 60 LABELS unit PASS_REGULAR_EXPRESSION
                       "^43c438d9f28edc9bfd49387db5cc06d0920214256168c2abff07736c474282b9")
endif()
