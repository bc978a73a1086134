# ctest -R Packaging (registered in tests/CMakeLists.txt): installs the build tree into a
# fresh temporary prefix, builds tests/consumer against it with find_package(scallop) and
# with `pkg-config --cflags --libs scallop`, runs both, runs tests/consumer/consumer.py on the
# installed Python module (when built), and removes the temporary files.
#
# cmake -DBUILD_DIR=... -DCONSUMER_DIR=... -DCONFIG=... -DGENERATOR=... -DCXX_COMPILER=...
#       -DPKG_CONFIG=... -DLIBDIR=... -DVERSION=... -DWITH_CAD=ON|OFF -DCOMPONENTS=a,b
#       [-DPYTHON=interpreter]
#       -P packaging_test.cmake
cmake_minimum_required(VERSION 3.25)

foreach(variable IN ITEMS BUILD_DIR CONSUMER_DIR GENERATOR CXX_COMPILER PKG_CONFIG LIBDIR VERSION COMPONENTS)
  if(NOT DEFINED ${variable} OR "${${variable}}" STREQUAL "")
    message(FATAL_ERROR "packaging_test.cmake: -D${variable}=... missing")
  endif()
endforeach()

string(REPLACE "," ";" COMPONENTS "${COMPONENTS}")

if(DEFINED ENV{TMPDIR} AND IS_DIRECTORY "$ENV{TMPDIR}")
  set(temp_root "$ENV{TMPDIR}")
else()
  set(temp_root "/tmp")
endif()
string(RANDOM LENGTH 10 suffix)
set(work "${temp_root}/scallop-packaging-${suffix}")
set(prefix "${work}/prefix")
file(MAKE_DIRECTORY "${work}")

# Every failure removes the temporary tree first.
function(fail message)
  file(REMOVE_RECURSE "${work}")
  message(FATAL_ERROR "${message}")
endfunction()

# Runs a command; fails with its output unless it exits 0. The output is left in `output`.
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT result EQUAL 0)
    fail("${what} failed (${result}):\n${ARGN}\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

set(config_args "")
if(NOT "${CONFIG}" STREQUAL "")
  set(config_args --config "${CONFIG}")
endif()

# 1. Install the components a consumer needs.
foreach(component IN LISTS COMPONENTS)
  run("cmake --install (${component})" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}"
      --component ${component} ${config_args})
endforeach()
foreach(file IN ITEMS "${LIBDIR}/cmake/scallop/scallopConfig.cmake" "${LIBDIR}/pkgconfig/scallop.pc"
                      include/scallop/paths/scallop_hull.hpp)
  if(NOT EXISTS "${prefix}/${file}")
    fail("not installed: ${file}")
  endif()
endforeach()

# 2. CMake: configure (only the temporary prefix searched for scallop), build, run.
set(build_type Release)
if(NOT "${CONFIG}" STREQUAL "")
  set(build_type "${CONFIG}")
endif()
run("configuring the consumer" "${CMAKE_COMMAND}" -S "${CONSUMER_DIR}" -B "${work}/build" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}" "-DCMAKE_BUILD_TYPE=${build_type}" "-DCMAKE_PREFIX_PATH=${prefix}"
    -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF "-DSCALLOP_CONSUMER_VERSION=${VERSION}"
    "-DSCALLOP_CONSUMER_CAD=${WITH_CAD}")
if(NOT output MATCHES "scallop ${VERSION} found: ${prefix}/")
  fail("the consumer did not find the package in ${prefix}:\n${output}")
endif()
run("building the consumer" "${CMAKE_COMMAND}" --build "${work}/build" ${config_args})
set(consumer "${work}/build/scallop-consumer")
if(NOT EXISTS "${consumer}" AND EXISTS "${work}/build/${CONFIG}/scallop-consumer")
  set(consumer "${work}/build/${CONFIG}/scallop-consumer")
endif()
# The hull's length (2 + pi / 2), then the plan's figures (the consumer checks them itself).
set(expected_output "^tool path length 3\\.570796326795\nplan: [0-9]+ progress reports, [0-9]+ passes, [0-9]+ bytes of G-code\n$")
run("running the CMake consumer" "${consumer}")
if(NOT output MATCHES "${expected_output}")
  fail("the CMake consumer printed: '${output}'")
endif()
string(STRIP "${output}" output)
message(STATUS "CMake consumer (scallop::cad linked: ${WITH_CAD}): ${output}")

# 3. pkg-config: the same main.cpp, core, io and jobs.
set(ENV{PKG_CONFIG_PATH} "${prefix}/${LIBDIR}/pkgconfig")
run("pkg-config --modversion scallop" "${PKG_CONFIG}" --modversion scallop)
string(STRIP "${output}" modversion)
if(NOT modversion STREQUAL VERSION)
  fail("pkg-config says scallop ${modversion}, expected ${VERSION}")
endif()
run("pkg-config --cflags --libs scallop" "${PKG_CONFIG}" --cflags --libs scallop)
string(STRIP "${output}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
run("compiling with pkg-config's flags" "${CXX_COMPILER}" -std=c++20 -O1 "${CONSUMER_DIR}/main.cpp" ${flags}
    -o "${work}/pkg-config-consumer")
run("running the pkg-config consumer" "${work}/pkg-config-consumer")
if(NOT output MATCHES "${expected_output}")
  fail("the pkg-config consumer printed: '${output}'")
endif()
string(STRIP "${output}" output)
message(STATUS "pkg-config consumer: ${output}")

# 4. Python (when the module was built, -DPYTHON=<interpreter>): the installed module, found
# under the prefix wherever its install rule put it, runs consumer.py's whole plan.
if(NOT "${PYTHON}" STREQUAL "")
  file(GLOB_RECURSE modules "${prefix}/*/scallop.cpython-*.so")
  list(LENGTH modules count)
  if(NOT count EQUAL 1)
    fail("expected one installed Python module under ${prefix}, found ${count}: ${modules}")
  endif()
  get_filename_component(module_dir "${modules}" DIRECTORY)
  run("running the Python consumer" "${CMAKE_COMMAND}" -E env "PYTHONPATH=${module_dir}" PYTHONDONTWRITEBYTECODE=1
      "${PYTHON}" "${CONSUMER_DIR}/consumer.py" "${prefix}")
  if(NOT output MATCHES "^plan: [0-9]+ progress reports, [0-9]+ passes, [0-9]+ bytes of G-code; cancelled half way\n$")
    fail("the Python consumer printed: '${output}'")
  endif()
  string(STRIP "${output}" output)
  message(STATUS "Python consumer: ${output}")
endif()

file(REMOVE_RECURSE "${work}")
