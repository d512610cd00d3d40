# libFuzzer targets (issue 13): every inbound decoder and validator, built only with
# -DOCTOMAP_RT_FUZZ=ON and clang (-DCMAKE_CXX_COMPILER=clang++-14). Each target compiles just
# the sources it exercises, with -fsanitize=fuzzer,address,undefined; the seed corpora are
# tests/fuzz/corpus/<target>/. tools/run-tests runs each for a bounded time; longer runs:
#   build-fuzz/tests/fuzz_octree_file -max_total_time=1800 CORPUS_COPY tests/fuzz/corpus/fuzz_octree_file
#
# To add a target for another inbound message: write tests/fuzz/fuzz_<name>.cpp around its
# validator, add one octomap_rt_add_fuzz_target line here and a seed directory
# tests/fuzz/corpus/fuzz_<name>/ (tools/run-tests finds it).
if(NOT OCTOMAP_RT_FUZZ)
  return()
endif()
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "OCTOMAP_RT_FUZZ needs clang: -DCMAKE_CXX_COMPILER=clang++-14")
endif()
set(FUZZ_DIR ${CMAKE_CURRENT_LIST_DIR})
if(OCTOMAP_RT_DEBUG_INFO)
  set(FUZZ_DEBUG_INFO ${OCTOMAP_RT_DEBUG_INFO})
else()
  set(FUZZ_DEBUG_INFO -g)
endif()
set(FUZZ_FLAGS -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
    ${FUZZ_DEBUG_INFO})

# octomap_rt_add_fuzz_target(<name> SOURCES ... [LIBS ...])
function(octomap_rt_add_fuzz_target name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${FUZZ_DIR}/${name}.cpp ${ARG_SOURCES})
  target_compile_options(${name} PRIVATE ${FUZZ_FLAGS})
  target_link_options(${name} PRIVATE ${FUZZ_FLAGS})
  target_include_directories(${name} PRIVATE ${CMAKE_SOURCE_DIR} ${CMAKE_SOURCE_DIR}/server ${CMAKE_SOURCE_DIR}/client)
  target_link_libraries(${name} PRIVATE octomap_rt_octomap Threads::Threads ${ARG_LIBS})
  set(OCTOMAP_RT_FUZZ_TARGETS ${OCTOMAP_RT_FUZZ_TARGETS} ${name} PARENT_SCOPE)
endfunction()

octomap_rt_add_fuzz_target(fuzz_scan_message
  SOURCES ${CMAKE_SOURCE_DIR}/server/daemon/intake/scan_validation.cpp ${CMAKE_SOURCE_DIR}/protocol/scan_decode.cpp
          ${CMAKE_SOURCE_DIR}/server/daemon/intake/reject_reason.cpp
          ${CMAKE_SOURCE_DIR}/protocol/wire_layout.cpp ${CMAKE_SOURCE_DIR}/protocol/inbound_checks.cpp
          ${CMAKE_SOURCE_DIR}/protocol/ids.cpp
          ${CMAKE_SOURCE_DIR}/server/core/prepare_scan.cpp ${CMAKE_SOURCE_DIR}/server/core/ray_tiles.cpp
          ${CMAKE_SOURCE_DIR}/server/core/map_frame.cpp ${CMAKE_SOURCE_DIR}/server/daemon/intake/scan_to_map.cpp
          ${CMAKE_SOURCE_DIR}/server/daemon/pipeline/scan_cost_gate.cpp
  LIBS octomap_rt_lcmtypes octomap_rt_lcm)
octomap_rt_add_fuzz_target(fuzz_scan_graph
  SOURCES ${CMAKE_SOURCE_DIR}/server/core/file_checks/scan_graph_check.cpp ${CMAKE_SOURCE_DIR}/client/scene/scan_set.cpp
          ${CMAKE_SOURCE_DIR}/server/core/map_frame.cpp)
octomap_rt_add_fuzz_target(fuzz_octree_file SOURCES ${CMAKE_SOURCE_DIR}/server/core/file_checks/octree_file_check.cpp)
file(GLOB FUZZ_QUERY_CORE ${CMAKE_SOURCE_DIR}/server/query/*.cpp ${CMAKE_SOURCE_DIR}/server/distance/*.cpp)
octomap_rt_add_fuzz_target(fuzz_query_message
  SOURCES ${CMAKE_SOURCE_DIR}/protocol/inbound_checks.cpp ${CMAKE_SOURCE_DIR}/server/daemon/queries/query_answers.cpp
          ${CMAKE_SOURCE_DIR}/server/daemon/queries/distance_answers.cpp ${CMAKE_SOURCE_DIR}/protocol/shards/shard_set.cpp
          ${CMAKE_SOURCE_DIR}/server/daemon/queries/box_frames.cpp
          ${CMAKE_SOURCE_DIR}/server/daemon/queries/field_patch.cpp ${CMAKE_SOURCE_DIR}/server/daemon/map/change_journal.cpp
          ${CMAKE_SOURCE_DIR}/server/octree/batched/morton_order.cpp
          ${CMAKE_SOURCE_DIR}/protocol/channels.cpp
          ${CMAKE_SOURCE_DIR}/protocol/wire_layout.cpp ${CMAKE_SOURCE_DIR}/protocol/zstd_codec.cpp ${FUZZ_QUERY_CORE}
  LIBS octomap_rt_lcmtypes octomap_rt_lcm zstd::libzstd_shared)
octomap_rt_add_fuzz_target(fuzz_map_request
  SOURCES ${CMAKE_SOURCE_DIR}/protocol/inbound_checks.cpp ${CMAKE_SOURCE_DIR}/protocol/wire_layout.cpp
          ${CMAKE_SOURCE_DIR}/protocol/ids.cpp ${CMAKE_SOURCE_DIR}/protocol/channels.cpp
          ${CMAKE_SOURCE_DIR}/protocol/map_request_rules.cpp
  LIBS octomap_rt_lcmtypes octomap_rt_lcm)
add_custom_target(octomap_rt_fuzz_targets DEPENDS ${OCTOMAP_RT_FUZZ_TARGETS})
