# Map queries and edits (server/query/) against the OctoMap library on real maps: OctoMap's
# own FR-079 map (geb079.bt) and maps OctoMap builds from ../shared/data scans. Each test
# also runs a deliberately wrong variant of its rule, which must disagree on the same inputs.
octomap_rt_add_test(query_test
  SOURCES $<TARGET_OBJECTS:octomap_rt_query_test_maps>
          ${CMAKE_CURRENT_LIST_DIR}/brute_force.cpp
          ${CMAKE_CURRENT_LIST_DIR}/point_ray_query_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/box_query_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/grid_query_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/map_edit_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/edit_cost_test.cpp
  LIBS octomap_rt_query
  TIMEOUT 600)

set_property(TEST query_test APPEND PROPERTY LABELS data)
set_property(TEST query_test APPEND PROPERTY LABELS slow)
