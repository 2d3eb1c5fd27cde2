# FindRecast.cmake: Recast (recastnavigation's voxelization library, Debian's librecast-dev),
# which ships no CMake config or pkg-config file. Defines Recast::Recast (headers included as
# <recastnavigation/Recast.h>) and Recast_FOUND. Used by vislib's build and by vislibConfig.cmake.
find_path(Recast_INCLUDE_DIR recastnavigation/Recast.h)
find_library(Recast_LIBRARY NAMES Recast)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(Recast REQUIRED_VARS Recast_LIBRARY Recast_INCLUDE_DIR)
if(Recast_FOUND AND NOT TARGET Recast::Recast)
  add_library(Recast::Recast UNKNOWN IMPORTED)
  set_target_properties(Recast::Recast PROPERTIES IMPORTED_LOCATION "${Recast_LIBRARY}"
                        INTERFACE_INCLUDE_DIRECTORIES "${Recast_INCLUDE_DIR}")
endif()
mark_as_advanced(Recast_INCLUDE_DIR Recast_LIBRARY)
