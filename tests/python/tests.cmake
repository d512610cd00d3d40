# Python client (client/python/) with Debian's python3, inside a network namespace per run.
find_program(PYTHON3 python3 PATHS /usr/bin NO_DEFAULT_PATH)
find_program(LCM_LOGGER lcm-logger)
if(PYTHON3 AND LCM_LOGGER)
  add_test(NAME python_udpm_transport_test
           COMMAND ${CMAKE_CURRENT_LIST_DIR}/run-in-netns ${PYTHON3} -m unittest -v test_udpm_transport
           WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
  set_tests_properties(python_udpm_transport_test PROPERTIES TIMEOUT 180 LABELS integration
    ENVIRONMENT "PYTHONPATH=${CMAKE_BINARY_DIR}/python:${CMAKE_CURRENT_LIST_DIR};OCTOMAP_RT_CLI=$<TARGET_FILE:octomap-rt>;PYTHONDONTWRITEBYTECODE=1")
  add_test(NAME python_map_client_test
           COMMAND ${CMAKE_CURRENT_LIST_DIR}/run-in-netns ${PYTHON3} -m unittest -v test_map_client
           WORKING_DIRECTORY ${CMAKE_CURRENT_LIST_DIR})
  set_tests_properties(python_map_client_test PROPERTIES TIMEOUT 300 LABELS integration
    ENVIRONMENT "PYTHONPATH=${CMAKE_BINARY_DIR}/python:${CMAKE_CURRENT_LIST_DIR};OCTOMAP_RT_CLI=$<TARGET_FILE:octomap-rt>;OCTOMAP_RT_SERVER=$<TARGET_FILE:octomap-rt-server>;PYTHONDONTWRITEBYTECODE=1")
else()
  message(WARNING "octomap-rt: python3 or lcm-logger missing: the Python client tests are not registered")
endif()
