# The fast CPU octree stage (issue 3): Morton order, buckets, the node counter, and the batched,
# multi-threaded update checked node for node against OctoMap's updateNode loop, on random
# batches and on the real data sets, after every scan.
# OCTOMAP_RT_OCTREE_TEST_QUICK=1 shortens the long cases (tools/run-tests uses it under TSan).
octomap_rt_add_test(octree_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/morton_order_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/node_count_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/random_batches_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/voxel_buckets_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/real_data_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/leaf_changes_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/full_blocks_test.cpp
          ${CMAKE_CURRENT_LIST_DIR}/worker_pool_test.cpp
          $<TARGET_OBJECTS:octomap_rt_octree_test_helpers>
  TIMEOUT 900)

# Regions, the subtrees at one depth that decay, clearing and eviction work on (octree/region.h),
# against OctoMap's own leaf iterator on its real FR-079 map.
octomap_rt_add_test(region_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/region_test.cpp TIMEOUT 120)

# Forgetting: decay (octree/decay.h) and clearing by distance (octree/distance_clearing.h)
# against their rules computed on OctoMap's own tree: the real FR-079 map and real scans with
# decay steps between them, whole sweeps and sweeps in slices.
octomap_rt_add_test(forgetting_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/decay_test.cpp ${CMAKE_CURRENT_LIST_DIR}/distance_clearing_test.cpp
          $<TARGET_OBJECTS:octomap_rt_octree_test_helpers>
  TIMEOUT 300)

# The memory bound's spill and restore on real scans: a map built with regions spilled and
# brought back is, once everything is back, the map built without the bound; and the bound's
# exact memory count equals OctoMap's walk after every kind of change (edits need the query layer).
octomap_rt_add_test(eviction_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/eviction_test.cpp
                    $<TARGET_OBJECTS:octomap_rt_octree_test_helpers>
  LIBS octomap_rt_query
  TIMEOUT 300)

# The memory bound's working set (octree/residency/working_set_window.h) on a stepped clock.
octomap_rt_add_test(working_set_window_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/working_set_window_test.cpp
                    LIBS octomap_rt_octree TIMEOUT 60)

# Versions kept per region (octree/versions/map_version.h), what whole-map readers read: OctoMap's .ot
# byte for byte after every real scan and while nodes above the region depth prune and expand.
octomap_rt_add_test(map_version_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/map_version_test.cpp
                    $<TARGET_OBJECTS:octomap_rt_octree_test_helpers>
  TIMEOUT 120)

set_property(TEST octree_test region_test map_version_test forgetting_test eviction_test APPEND PROPERTY LABELS data)
set_property(TEST octree_test APPEND PROPERTY LABELS slow)
