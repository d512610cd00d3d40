# client/cli/status/: `octomap-rt status`: the server's OCTOMAP_RT_STATUS as terminal text or JSON.
add_library(octomap_rt_status STATIC ${CMAKE_CURRENT_LIST_DIR}/status_text.cpp ${CMAKE_CURRENT_LIST_DIR}/status_json.cpp)
target_include_directories(octomap_rt_status PUBLIC ${CMAKE_CURRENT_LIST_DIR}/../..)
target_link_libraries(octomap_rt_status PUBLIC octomap_rt_lcmtypes)
