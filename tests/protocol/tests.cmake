# The map protocol's codecs and pre-decode checks, and the client's chunk assembly.
octomap_rt_add_test(protocol_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/protocol_test.cpp ${CMAKE_CURRENT_LIST_DIR}/protocol_rules_test.cpp
                    LIBS octomap_rt_protocol octomap_rt_map_client TIMEOUT 120)

# The Python and Java clients' generated tables against the C++ home of the protocol.
octomap_rt_add_test(protocol_table_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/protocol_table_test.cpp
                    LIBS octomap_rt_protocol TIMEOUT 60)
if(NOT OCTOMAP_RT_JAVA_TABLE)
  set(OCTOMAP_RT_JAVA_TABLE "")
endif()
target_compile_definitions(protocol_table_test PRIVATE OCTOMAP_RT_PYTHON_TABLE="${CMAKE_BINARY_DIR}/python/octomap_rt/protocol_table.py"
                           OCTOMAP_RT_JAVA_TABLE="${OCTOMAP_RT_JAVA_TABLE}" OCTOMAP_RT_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
add_dependencies(protocol_table_test octomap_rt_python)
if(TARGET octomap_rt_java_examples)
  add_dependencies(protocol_table_test octomap_rt_java_examples)
endif()
# The MAC of map edits: the protocol's test vector, every field covered.
octomap_rt_add_test(edit_mac_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/edit_mac_test.cpp LIBS octomap_rt_protocol TIMEOUT 60)
