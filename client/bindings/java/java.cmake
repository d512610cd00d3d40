# client/bindings/java/: Java programs against our types jar (compiled here so they keep up with the
# types): the status listener and a signed map edit (javax.crypto's HMAC).
# ProtocolTable.java (channel names, limits, default URL, version) is generated from protocol/ by
# tools/protocol-table, so the example never spells a channel name itself.
if(TARGET octomap_rt_lcmtypes_jar)
  include(UseJava)
  set(ORT_JAVA_TABLE ${CMAKE_CURRENT_BINARY_DIR}/java/ProtocolTable.java)
  add_custom_command(
    OUTPUT ${ORT_JAVA_TABLE}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_CURRENT_BINARY_DIR}/java
    COMMAND ${CMAKE_SOURCE_DIR}/tools/protocol-table java ${ORT_JAVA_TABLE}
    DEPENDS ${CMAKE_SOURCE_DIR}/tools/protocol-table ${CMAKE_SOURCE_DIR}/protocol/channels.h
            ${CMAKE_SOURCE_DIR}/protocol/limits.h ${CMAKE_SOURCE_DIR}/protocol/lcm_url.h
            ${CMAKE_SOURCE_DIR}/protocol/version.h
    COMMENT "ProtocolTable.java (tools/protocol-table)"
    VERBATIM)
  add_jar(octomap_rt_java_examples
          SOURCES ${CMAKE_CURRENT_LIST_DIR}/examples/StatusListener.java ${CMAKE_CURRENT_LIST_DIR}/examples/MapEdit.java ${ORT_JAVA_TABLE}
          INCLUDE_JARS ${LCM_JAR} octomap_rt_lcmtypes_jar
          OUTPUT_NAME octomap_rt_java_examples)
  set(OCTOMAP_RT_JAVA_TABLE ${ORT_JAVA_TABLE} CACHE INTERNAL "generated ProtocolTable.java")
endif()
