# ctest -R Layout (registered in tests/CMakeLists.txt): the layers of src/ and include/scallop/
# depend one way, geometry <- slicing <- paths <- io <- jobs (cad beside io, on geometry and
# paths); support/ holds private helpers any layer may use. Every #include of a layer
# folder in a file of a lower layer fails the test, naming the file and the line.
#
# cmake -DSOURCE_DIR=<the project's root> -P layering_test.cmake
cmake_minimum_required(VERSION 3.25)

set(rank_support 0)
set(rank_geometry 1)
set(rank_slicing 2)
set(rank_paths 3)
set(rank_cad 4)
set(rank_io 4)
set(rank_jobs 5)
set(layers support geometry slicing paths cad io jobs)

set(violations "")
set(checked 0)
foreach(layer IN LISTS layers)
  file(GLOB_RECURSE files "${SOURCE_DIR}/src/${layer}/*.[ch]pp" "${SOURCE_DIR}/include/scallop/${layer}/*.hpp")
  foreach(file IN LISTS files)
    math(EXPR checked "${checked} + 1")
    file(STRINGS "${file}" lines REGEX "^#include \"(scallop/)?(support|geometry|slicing|paths|cad|io|jobs)/")
    foreach(line IN LISTS lines)
      string(REGEX REPLACE "^#include \"(scallop/)?([a-z]+)/.*" "\\2" target "${line}")
      # cad and io are side by side: neither may include the other.
      if(rank_${target} GREATER rank_${layer} OR (rank_${target} EQUAL rank_${layer} AND NOT target STREQUAL layer))
        file(RELATIVE_PATH shown "${SOURCE_DIR}" "${file}")
        string(APPEND violations "\n  ${shown}: ${line} (${layer} may not depend on ${target})")
      endif()
    endforeach()
  endforeach()
endforeach()
if(checked LESS 50)
  message(FATAL_ERROR "layering_test.cmake: only ${checked} files found under ${SOURCE_DIR}: wrong SOURCE_DIR?")
endif()
if(NOT violations STREQUAL "")
  message(FATAL_ERROR "includes against the layers:${violations}")
endif()
message(STATUS "${checked} files: every include goes down the layers")
