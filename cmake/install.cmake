# Installation and export (docs/runtime.md, "Installing and linking"), included by the top-level
# CMakeLists.txt. Two export sets:
#   vislibRuntimeTargets: pvs_format, vislib_runtime (static, C++ and C API) and
#                         vislib_runtime_shared (libvislib_runtime.so, C API only): standard library only.
#   vislibTargets:        the six corners and the umbrella vislib::vislib (full build only).
# vislibConfig.cmake loads the first always and the second only for COMPONENTS vislib, so
# find_package(vislib COMPONENTS runtime) looks for no third-party package.
include(CMakePackageConfigHelpers)
set(VISLIB_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/vislib)

install(TARGETS pvs_format vislib_runtime vislib_runtime_shared EXPORT vislibRuntimeTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
set_target_properties(vislib_runtime_shared PROPERTIES EXPORT_NAME runtime_shared)
set_target_properties(vislib_runtime PROPERTIES EXPORT_NAME runtime)
install(EXPORT vislibRuntimeTargets NAMESPACE vislib:: DESTINATION ${VISLIB_CMAKE_DIR}
        FILE vislibRuntimeTargets.cmake)
# Public headers keep their in-tree paths under include/vislib/ ("runtime/pvs_runtime_c.h",
# "pvs_format/pvs_format.h", "vislib/scene/scene.h"), so sources compile unchanged against an install.
install(FILES ${PROJECT_SOURCE_DIR}/pvs_format/pvs_format.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vislib/pvs_format)
install(FILES ${PROJECT_SOURCE_DIR}/runtime/pvs_runtime.h ${PROJECT_SOURCE_DIR}/runtime/pvs_runtime_c.h
              ${PROJECT_SOURCE_DIR}/runtime/near_far.h ${PROJECT_SOURCE_DIR}/runtime/near_far_c.h
              ${PROJECT_SOURCE_DIR}/runtime/ods.h
              ${PROJECT_BINARY_DIR}/generated/runtime/vislib_version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vislib/runtime)

# The license travels with every install, runtime-only included (<prefix>/share/doc/vislib/LICENSE).
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})

set(VISLIB_INSTALLED_COMPONENTS runtime)
if(NOT VISLIB_RUNTIME_ONLY)
  list(APPEND VISLIB_INSTALLED_COMPONENTS vislib)
  install(TARGETS pvs RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # The image module that vislib::eval loads on first image I/O (vislib/CMakeLists.txt).
  if(TARGET vislib_image_oiio)
    install(TARGETS vislib_image_oiio LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/vislib)
    # For vislibConfig.cmake's vislib_IMAGE_MODULE, relative to the prefix.
    set(VISLIB_IMAGE_MODULE_IN_PREFIX
        ${CMAKE_INSTALL_LIBDIR}/vislib/${CMAKE_SHARED_MODULE_PREFIX}vislib_image_oiio${CMAKE_SHARED_MODULE_SUFFIX})
  endif()
  set(_corner_targets)
  get_directory_property(_corners DIRECTORY ${PROJECT_SOURCE_DIR}/vislib DEFINITION VISLIB_CORNERS)
  foreach(name ${_corners})
    list(APPEND _corner_targets vislib_${name})
    set_target_properties(vislib_${name} PROPERTIES EXPORT_NAME ${name})
    target_include_directories(vislib_${name} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
                                                         $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/vislib>)
    install(DIRECTORY ${PROJECT_SOURCE_DIR}/vislib/${name} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vislib
            FILES_MATCHING PATTERN "*.h")
  endforeach()
  target_include_directories(vislib INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  install(TARGETS ${_corner_targets} vislib EXPORT vislibTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT vislibTargets NAMESPACE vislib:: DESTINATION ${VISLIB_CMAKE_DIR} FILE vislibTargets.cmake)
endif()

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vislibConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/cmake/vislibConfig.cmake INSTALL_DESTINATION ${VISLIB_CMAKE_DIR})
# 0.x: a minor version may break the API, so only the same MAJOR.MINOR is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cmake/vislibConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cmake/vislibConfig.cmake ${PROJECT_BINARY_DIR}/cmake/vislibConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindRecast.cmake
        DESTINATION ${VISLIB_CMAKE_DIR})

# pkg-config for the C API: `cc app.c $(pkg-config --cflags --libs vislib_runtime)`. Its paths are
# relative to the .pc file's own folder (${pcfiledir}), not the configured prefix, so an install
# works at any `cmake --install --prefix` and after being moved (an absolute libdir or includedir
# given at configure time stays absolute).
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(VISLIB_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
else()
  file(RELATIVE_PATH _up /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
  string(REGEX REPLACE "/$" "" _up "${_up}")
  set(VISLIB_PC_PREFIX "\${pcfiledir}/${_up}")  # ${pcfiledir}/../..
endif()
foreach(_kind LIBDIR INCLUDEDIR)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${_kind}}")
    set(VISLIB_PC_${_kind} "${CMAKE_INSTALL_${_kind}}")
  else()
    set(VISLIB_PC_${_kind} "\${prefix}/${CMAKE_INSTALL_${_kind}}")
  endif()
endforeach()
configure_file(${PROJECT_SOURCE_DIR}/cmake/vislib_runtime.pc.in ${PROJECT_BINARY_DIR}/cmake/vislib_runtime.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/cmake/vislib_runtime.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
