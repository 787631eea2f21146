# codemark-accuracy-map, the paper's error maps on renders against AprilTag:
# a benchmark tool whose source lives with the benchmarks, built and
# installed with the tools (the tests' bad-input sweep runs it), included
# from the top-level CMakeLists.txt.
if(TARGET codemark::sim AND TARGET codemark::detect)
  find_library(CODEMARK_APRILTAG_LIB apriltag)
  # image_u8_destroy lives in the utils library of Debian's AprilTag 3 build.
  find_library(CODEMARK_APRILTAG_UTILS_LIB apriltag-utils)
  find_path(CODEMARK_APRILTAG_INCLUDE apriltag.h PATH_SUFFIXES apriltag)
  if(CODEMARK_APRILTAG_LIB AND CODEMARK_APRILTAG_UTILS_LIB AND CODEMARK_APRILTAG_INCLUDE)
    codemark_add_app(codemark-accuracy-map SOURCES ${CMAKE_CURRENT_LIST_DIR}/main.cpp
      ${CMAKE_CURRENT_LIST_DIR}/accuracy_map.cpp
      LIBS codemark::pose codemark::pipeline codemark::sim codemark::detect opencv_imgproc opencv_imgcodecs
           ${CODEMARK_APRILTAG_LIB} ${CODEMARK_APRILTAG_UTILS_LIB})
    target_include_directories(codemark-accuracy-map PRIVATE ${CODEMARK_APRILTAG_INCLUDE})
    set_target_properties(codemark-accuracy-map PROPERTIES
      RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench/accuracy_map)
  else()
    message(STATUS "codemark-accuracy-map: AprilTag 3 not found, tool not built")
  endif()
endif()
