include(${CMAKE_CURRENT_LIST_DIR}/integration_tests.cmake)
