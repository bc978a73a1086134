# install(): included by the top-level CMakeLists.txt when SCALLOP_INSTALL is on.
#
# Components: scallop_Development (static libraries, headers, the CMake package and
# scallop.pc) and scallop_Runtime (the scallop program; shared libraries when
# BUILD_SHARED_LIBS). Tests and benchmarks are not installed. The Python module's rule is in
# python/CMakeLists.txt (component scallop_Python, SCALLOP_PYTHON_INSTALL_DIR).
#
# The CMake package: find_package(scallop) gives scallop::core, scallop::io, scallop::jobs
# and scallop::scallop (all three); find_package(scallop COMPONENTS cad) adds scallop::cad (and finds
# OpenCASCADE) when scallop was built with SCALLOP_BUILD_CAD.
include(CMakePackageConfigHelpers)

set(SCALLOP_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/scallop"
    CACHE STRING "Where scallopConfig.cmake is installed (relative to the prefix)")
mark_as_advanced(SCALLOP_INSTALL_CMAKEDIR)

# The targets of one export set (archives and headers' link files for development, shared
# libraries and programs at run time) and the set's targets file, as scallop::<name>.
function(scallop_install_export export_set)
  install(TARGETS ${ARGN}
    EXPORT ${export_set}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT scallop_Development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT scallop_Runtime
            NAMELINK_COMPONENT scallop_Development
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT scallop_Runtime)
  install(EXPORT ${export_set}
    NAMESPACE scallop::
    DESTINATION ${SCALLOP_INSTALL_CMAKEDIR}
    COMPONENT scallop_Development)
endfunction()

scallop_install_export(scallopTargets scallop_core scallop_io scallop_jobs scallop)

# The public headers, by layer (include/scallop/<layer>/), cad/ only with scallop::cad. The
# globs run at install time.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/scallop
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  COMPONENT scallop_Development
  FILES_MATCHING PATTERN "*.hpp" PATTERN "cad" EXCLUDE)

if(SCALLOP_BUILD_CAD)
  # An export set of its own, so that find_package(scallop) looks for OpenCASCADE only
  # when scallop::cad is asked for.
  scallop_install_export(scallopCadTargets scallop_cad)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/scallop/cad
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/scallop
    COMPONENT scallop_Development)
endif()

if(SCALLOP_BUILD_CLI)
  install(TARGETS scallop-cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT scallop_Runtime)
endif()

# scallopConfig.cmake and its version file. 0.x: a minor version may break the interface.
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/scallopConfig.cmake.in
  ${PROJECT_BINARY_DIR}/scallopConfig.cmake
  INSTALL_DESTINATION ${SCALLOP_INSTALL_CMAKEDIR}
  NO_SET_AND_CHECK_MACRO)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/scallopConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/scallopConfig.cmake ${PROJECT_BINARY_DIR}/scallopConfigVersion.cmake
  DESTINATION ${SCALLOP_INSTALL_CMAKEDIR}
  COMPONENT scallop_Development)

# scallop.pc: core and io (scallop::cad has no pkg-config file: OpenCASCADE ships none).
# Relocatable (prefix from ${pcfiledir}) unless a directory was set absolute. The static
# archives need their dependencies on every link line, so for a static build they are in
# Requires and Libs (plain `pkg-config --libs scallop` links); for a shared build in the
# .private fields.
set(scallop_pc_dir "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(SCALLOP_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(SCALLOP_PC_LIBDIR "${CMAKE_INSTALL_FULL_LIBDIR}")
  set(SCALLOP_PC_INCLUDEDIR "${CMAKE_INSTALL_FULL_INCLUDEDIR}")
else()
  file(RELATIVE_PATH scallop_pc_up "/${scallop_pc_dir}" "/")
  string(REGEX REPLACE "/$" "" scallop_pc_up "${scallop_pc_up}")
  set(SCALLOP_PC_PREFIX "\${pcfiledir}/${scallop_pc_up}")
  set(SCALLOP_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
  set(SCALLOP_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
set(scallop_pc_requires "fmt >= ${fmt_VERSION_MAJOR}, polyclipping, qhull_r")
set(scallop_pc_libs "${CMAKE_THREAD_LIBS_INIT}")
if(BUILD_SHARED_LIBS)
  set(SCALLOP_PC_REQUIRES "")
  set(SCALLOP_PC_REQUIRES_PRIVATE "${scallop_pc_requires}")
  set(SCALLOP_PC_LIBS "")
  set(SCALLOP_PC_LIBS_PRIVATE "${scallop_pc_libs}")
else()
  set(SCALLOP_PC_REQUIRES "${scallop_pc_requires}")
  set(SCALLOP_PC_REQUIRES_PRIVATE "")
  set(SCALLOP_PC_LIBS "${scallop_pc_libs}")
  set(SCALLOP_PC_LIBS_PRIVATE "")
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/scallop.pc.in ${PROJECT_BINARY_DIR}/scallop.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/scallop.pc
  DESTINATION ${scallop_pc_dir}
  COMPONENT scallop_Development)
