# The room-frame benchmark compares with OctoMap when Debian's liboctomap-dev is installed.
if(octomap_FOUND)
  target_include_directories(${stem} SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(${stem} PRIVATE ${OCTOMAP_LIBRARIES})
  target_compile_definitions(${stem} PRIVATE INTERVOX_BENCH_HAVE_OCTOMAP)
else()
  message(STATUS "bench_raycast: OctoMap not found, the OctoMap comparison is skipped")
endif()
