# client/shard_client/: one map from a shard set (docs/PROTOCOL.md, "Shards"): the shards of a
# namespace found by their statuses, a snapshot from each merged into one map, and queries
# routed by region. Used by `octomap-rt map get --shards`, `status`, `query --shards`.
add_library(octomap_rt_shard_client STATIC ${CMAKE_CURRENT_LIST_DIR}/shard_roster.cpp
            ${CMAKE_CURRENT_LIST_DIR}/shard_snapshot.cpp ${CMAKE_CURRENT_LIST_DIR}/shard_queries.cpp
            ${CMAKE_CURRENT_LIST_DIR}/shard_distance.cpp ${CMAKE_CURRENT_LIST_DIR}/shard_grid_edit.cpp
            ${CMAKE_CURRENT_LIST_DIR}/shard_rays.cpp ${CMAKE_CURRENT_LIST_DIR}/shard_mirror.cpp
            ${CMAKE_CURRENT_LIST_DIR}/shard_region.cpp)
target_include_directories(octomap_rt_shard_client PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
target_link_libraries(octomap_rt_shard_client PUBLIC octomap_rt_map_client octomap_rt_query_client octomap_rt_core
                      octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_lcm Threads::Threads)
octomap_rt_lcm_handler_sources(octomap_rt_shard_client ${CMAKE_CURRENT_LIST_DIR}/shard_roster.cpp)
