include(${CMAKE_CURRENT_LIST_DIR}/integration_tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/unit_tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/viewer_tests.cmake)
