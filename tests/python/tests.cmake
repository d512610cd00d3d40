# Python client (client/bindings/python/) with Debian's python3, inside a network namespace per run.
find_program(PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(LCM_LOGGER lcm-logger)
set(ORT_PY_TEST_ENV "PYTHONPATH=${CMAKE_BINARY_DIR}/python:${CMAKE_CURRENT_LIST_DIR}"
    "OCTOMAP_RT_CLI=$<TARGET_FILE:octomap-rt>" "OCTOMAP_RT_SERVER=$<TARGET_FILE:octomap-rt-server>"
    "PYTHONDONTWRITEBYTECODE=1" "OCTOMAP_RT_DATA=${OCTOMAP_RT_DATA_DIR}"
    "OCTOMAP_RT_PUBLISH_EXAMPLE=$<TARGET_FILE:octomap-rt-publish-example>")
# The Java examples (client/bindings/java/), when a JDK built them: test_namespaces runs them.
if(TARGET octomap_rt_java_examples)
  list(APPEND ORT_PY_TEST_ENV "OCTOMAP_RT_JAVA_CP=${LCM_JAR}:$<TARGET_PROPERTY:octomap_rt_lcmtypes_jar,JAR_FILE>:$<TARGET_PROPERTY:octomap_rt_java_examples,JAR_FILE>")
endif()

# octomap_rt_add_python_test(<name> <module> <timeout>): `python3 -m unittest <module>` in its namespace.
function(octomap_rt_add_python_test name module timeout)
  add_test(NAME ${name} COMMAND ${CMAKE_CURRENT_FUNCTION_LIST_DIR}/run-in-netns ${PYTHON3} -m unittest -v ${module}
           WORKING_DIRECTORY ${CMAKE_CURRENT_FUNCTION_LIST_DIR})
  set_tests_properties(${name} PROPERTIES TIMEOUT ${timeout} LABELS integration ENVIRONMENT "${ORT_PY_TEST_ENV}")
endfunction()

if(PYTHON3 AND LCM_LOGGER)
  octomap_rt_add_python_test(python_udpm_transport_test test_udpm_transport 180)
  octomap_rt_add_python_test(python_map_client_test test_map_client 300)
  octomap_rt_add_python_test(python_map_service_test test_map_service 300)
  octomap_rt_add_python_test(python_queries_test test_queries 300)
  octomap_rt_add_python_test(python_planner_test test_planner 300)
  octomap_rt_add_python_test(python_namespaces_test test_namespaces 300)
  # README's "Connect your robot": the C++ and the Python producer examples against a real server.
  octomap_rt_add_python_test(python_producers_test test_producers 300)
  octomap_rt_add_python_test(python_edits_test test_edits 300)
  octomap_rt_add_python_test(python_cli_edges_test test_cli_edges 300)
  # A mirror that follows deltas, and resyncs on a new epoch (a reset).
  octomap_rt_add_python_test(python_map_mirror_test test_map_mirror 300)
  # Issue 26: the Python shard client against three shards and one whole daemon.
  octomap_rt_add_python_test(python_shards_test test_shards 300)
  # Every shard's deltas in one mirror (real 3DTK scans), one shard's new epoch, a late shard.
  octomap_rt_add_python_test(python_shard_mirror_test test_shard_mirror 300)
else()
  message(WARNING "octomap-rt: python3 or lcm-logger missing: the Python client tests are not registered")
endif()
