# The map for LCM's OctoMap viewers (octomap.raw_t on OCTOMAP). The check type is generated
# here from the viewers' field list, independently of lcmtypes/.
set(VIEWER_CHECK_DIR ${CMAKE_CURRENT_BINARY_DIR}/viewer_check)
add_custom_command(
  OUTPUT ${VIEWER_CHECK_DIR}/libbot_copy/raw_t.hpp
  COMMAND ${LCM_GEN} --cpp --cpp-std c++11 --cpp-hpath ${VIEWER_CHECK_DIR} ${CMAKE_CURRENT_LIST_DIR}/libbot_copy_raw_t.lcm
  DEPENDS ${CMAKE_CURRENT_LIST_DIR}/libbot_copy_raw_t.lcm
  COMMENT "lcm-gen libbot_copy_raw_t.lcm (test copy of the viewers' type)"
  VERBATIM)
add_custom_target(viewer_check_types DEPENDS ${VIEWER_CHECK_DIR}/libbot_copy/raw_t.hpp)

octomap_rt_add_test(server_octomap_raw_test SOURCES ${CMAKE_CURRENT_LIST_DIR}/octomap_raw_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/bt_conformance_test.cpp
                    ${CMAKE_CURRENT_LIST_DIR}/octomap_raw_publisher_test.cpp
                    LIBS octomap_rt_daemon TIMEOUT 120)
add_dependencies(server_octomap_raw_test viewer_check_types)
target_include_directories(server_octomap_raw_test PRIVATE ${VIEWER_CHECK_DIR})

# The real server publishing OCTOMAP in a network namespace, received with a default UDP buffer.
octomap_rt_add_integration_test(server_octomap_raw_integration_test 300)
add_dependencies(server_octomap_raw_integration_test viewer_check_types)
target_include_directories(server_octomap_raw_integration_test PRIVATE ${VIEWER_CHECK_DIR})
