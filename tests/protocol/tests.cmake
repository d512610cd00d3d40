# The map protocol's codecs and pre-decode checks, and the client's chunk assembly.
octomap_rt_add_test(protocol_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/protocol_test.cpp
                    LIBS octomap_rt_protocol octomap_rt_map_client TIMEOUT 120)
