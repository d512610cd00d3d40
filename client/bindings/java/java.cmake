# client/bindings/java/: a Java program against our types jar (compiled here so it keeps up with the types).
if(TARGET octomap_rt_lcmtypes_jar)
  include(UseJava)
  add_jar(octomap_rt_java_examples
          SOURCES ${CMAKE_CURRENT_LIST_DIR}/examples/StatusListener.java
          INCLUDE_JARS ${LCM_JAR} octomap_rt_lcmtypes_jar
          OUTPUT_NAME octomap_rt_java_examples)
endif()
