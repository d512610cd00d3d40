# The exact distance transform (server/distance/) on real maps: every cell of sampled boxes
# against a brute-force nearest-obstacle search written from the definition (one OctoMap
# search() per finest voxel), and OctoMap's own DynamicEDTOctomap (libdynamicedt3d-dev)
# where the two definitions agree. The Vulkan EDT (gpu_distance_test) is compared with the
# CPU one on the same grids, and skips where there is no Vulkan device.
find_package(dynamicEDT3D QUIET)
octomap_rt_add_test(distance_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/distance_exactness_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/brute_distance.cpp
          ${CMAKE_CURRENT_LIST_DIR}/field_cache_test.cpp
          $<TARGET_OBJECTS:octomap_rt_query_test_maps>
  LIBS octomap_rt_distance
  TIMEOUT 600)
if(dynamicEDT3D_FOUND)
  target_sources(distance_test PRIVATE ${CMAKE_CURRENT_LIST_DIR}/dynamic_edt_test.cpp)
  target_include_directories(distance_test PRIVATE ${DYNAMICEDT3D_INCLUDE_DIRS})
  target_link_libraries(distance_test PRIVATE ${DYNAMICEDT3D_LIBRARIES})
else()
  message(WARNING "octomap-rt: libdynamicedt3d-dev not found: distance_test runs without its DynamicEDTOctomap check")
endif()

set_property(TEST distance_test APPEND PROPERTY LABELS data)
set_property(TEST distance_test APPEND PROPERTY LABELS slow)
