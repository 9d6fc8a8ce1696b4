# The grid file comparison writes OctoMap's .bt and .ot through Debian's liboctomap-dev.
if(octomap_FOUND)
  target_include_directories(${stem} SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(${stem} PRIVATE ${OCTOMAP_LIBRARIES})
  target_compile_definitions(${stem} PRIVATE INTERVOX_BENCH_HAVE_OCTOMAP)
else()
  message(STATUS "bench_grid_file: OctoMap not found, the .bt/.ot columns are skipped")
endif()
