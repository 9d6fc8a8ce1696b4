# Finds libzstd (the grid file format compresses with it) and makes sure the imported target
# zstd::libzstd_shared exists: from zstd's own CMake package (Debian's libzstd-dev ships one) or,
# failing that, from pkg-config (libzstd.pc). Used by the build and by the installed package config.
# Sets intervox_zstd_FOUND.
if(NOT TARGET zstd::libzstd_shared)
  find_package(zstd CONFIG QUIET)
endif()
if(NOT TARGET zstd::libzstd_shared)
  find_package(PkgConfig QUIET)
  if(PkgConfig_FOUND)
    pkg_check_modules(INTERVOX_ZSTD QUIET IMPORTED_TARGET libzstd)
  endif()
  if(TARGET PkgConfig::INTERVOX_ZSTD)
    add_library(zstd::libzstd_shared INTERFACE IMPORTED)
    target_link_libraries(zstd::libzstd_shared INTERFACE PkgConfig::INTERVOX_ZSTD)
  endif()
endif()
if(TARGET zstd::libzstd_shared)
  set(intervox_zstd_FOUND TRUE)
else()
  set(intervox_zstd_FOUND FALSE)
endif()
