# Installation: libraries, header, CMake package and pkg-config file.
#
# Included from the root CMakeLists.txt after the library targets exist.
# A consumer project then does
#
#   find_package(wetcloth CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE wetcloth::wetcloth)         # shared
#   target_link_libraries(app PRIVATE wetcloth::wetcloth_static)  # static
#
# or, without CMake:  cc app.c $(pkg-config --cflags --libs wetcloth)
#
# Only `wetcloth` and `wetcloth_static` are exported. The internal INTERFACE
# targets (wc_flags, wc_internal, wc_objects) stay out of the export set: the
# libraries use wc_flags only through $<BUILD_INTERFACE:...>.

include(CMakePackageConfigHelpers)

set(WC_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/wetcloth"
    CACHE STRING "Where the CMake package files of wetcloth are installed, relative to the prefix")
set(WC_INSTALL_PKGCONFIGDIR "${CMAKE_INSTALL_LIBDIR}/pkgconfig"
    CACHE STRING "Where wetcloth.pc is installed, relative to the prefix")
mark_as_advanced(WC_INSTALL_CMAKEDIR WC_INSTALL_PKGCONFIGDIR)

install(TARGETS wetcloth wetcloth_static
  EXPORT wetclothTargets
  RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}" COMPONENT runtime
  LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT runtime
          NAMELINK_COMPONENT development
  ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}" COMPONENT development)

install(FILES "${PROJECT_SOURCE_DIR}/include/wetcloth.h"
  DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}" COMPONENT development)

install(EXPORT wetclothTargets
  NAMESPACE wetcloth::
  FILE wetclothTargets.cmake
  DESTINATION "${WC_INSTALL_CMAKEDIR}" COMPONENT development)

# The config file re-finds what the exported targets link publicly:
# libccd (always) and OpenMP (when built with WC_OPENMP).
set(WC_CONFIG_USES_OPENMP ${WC_OPENMP})
configure_package_config_file(
  "${CMAKE_CURRENT_LIST_DIR}/wetclothConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/cmake/wetclothConfig.cmake"
  INSTALL_DESTINATION "${WC_INSTALL_CMAKEDIR}"
  NO_SET_AND_CHECK_MACRO
  NO_CHECK_REQUIRED_COMPONENTS_MACRO)

# 0.x: a new minor version may change the API, so only the same minor matches.
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/cmake/wetclothConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}"
  COMPATIBILITY SameMinorVersion)

install(FILES
  "${PROJECT_BINARY_DIR}/cmake/wetclothConfig.cmake"
  "${PROJECT_BINARY_DIR}/cmake/wetclothConfigVersion.cmake"
  DESTINATION "${WC_INSTALL_CMAKEDIR}" COMPONENT development)

# pkg-config. The prefix is written relative to the .pc file's own folder
# (${pcfiledir}), so the file stays right when the install is relocated with
# `cmake --install build --prefix DIR` or DESTDIR.
if(IS_ABSOLUTE "${WC_INSTALL_PKGCONFIGDIR}")
  set(WC_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH _wc_pc_up "/wc_prefix/${WC_INSTALL_PKGCONFIGDIR}" "/wc_prefix")
  string(REGEX REPLACE "/$" "" _wc_pc_up "${_wc_pc_up}")
  set(WC_PC_PREFIX "\${pcfiledir}/${_wc_pc_up}")
endif()
foreach(_wc_dir LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${_wc_dir}}")
    set(WC_PC_${_wc_dir} "${CMAKE_INSTALL_${_wc_dir}}")
  else()
    set(WC_PC_${_wc_dir} "\${prefix}/${CMAKE_INSTALL_${_wc_dir}}")
  endif()
endforeach()
set(WC_PC_LIBS_PRIVATE "-lccd -lm")
if(WC_OPENMP)
  # OpenMP_C_FLAGS is what the compiler needs to link libgomp (-fopenmp for gcc).
  string(APPEND WC_PC_LIBS_PRIVATE " ${OpenMP_C_FLAGS}")
endif()
configure_file("${CMAKE_CURRENT_LIST_DIR}/wetcloth.pc.in"
               "${PROJECT_BINARY_DIR}/cmake/wetcloth.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/cmake/wetcloth.pc"
  DESTINATION "${WC_INSTALL_PKGCONFIGDIR}" COMPONENT development)
