# client/query_client/: the client side of the query service (request/reply over LCM), its
# command-line arguments and JSON output: used by `octomap-rt query|map` and client/examples/.
# No renderer: the grid's picture is the CLI's (cli/grid_picture).
add_library(octomap_rt_query_client STATIC ${CMAKE_CURRENT_LIST_DIR}/query_client.cpp
            ${CMAKE_CURRENT_LIST_DIR}/query_json.cpp ${CMAKE_CURRENT_LIST_DIR}/query_args.cpp
            ${CMAKE_CURRENT_LIST_DIR}/distance_box.cpp)
# Installed (cmake/install.cmake) as octomap_rt::query_client; its API is in ort::client (client.h).
set_target_properties(octomap_rt_query_client PROPERTIES POSITION_INDEPENDENT_CODE ON EXPORT_NAME query_client)
target_include_directories(octomap_rt_query_client PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_LIST_DIR}/..>
                           $<INSTALL_INTERFACE:include/octomap_rt>)
target_link_libraries(octomap_rt_query_client PUBLIC octomap_rt_protocol octomap_rt_lcmtypes octomap_rt_lcm)
add_library(octomap_rt::query_client ALIAS octomap_rt_query_client)
octomap_rt_lcm_handler_sources(octomap_rt_query_client ${CMAKE_CURRENT_LIST_DIR}/query_client.cpp)
