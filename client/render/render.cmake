# client/render/: map pictures (`octomap-rt render`): OcTree leaves -> software rasterizer -> PNG.
find_package(PNG REQUIRED)  # libpng-dev
file(GLOB RENDER_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.cpp)
add_library(octomap_rt_render STATIC ${RENDER_SOURCES})
target_include_directories(octomap_rt_render PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
target_link_libraries(octomap_rt_render PUBLIC octomap_rt_octomap PRIVATE octomap_rt_clock PNG::PNG)
