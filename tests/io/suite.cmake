# io tests: PNG through libpng (intervox::png), OctoMap interop checked against Debian's liboctomap.
if(NOT TARGET intervox::png)
  message(FATAL_ERROR "the io tests need libpng (libpng-dev)")
endif()
target_link_libraries(${suite_target} PRIVATE intervox::png)
target_compile_definitions(${suite_target} PRIVATE
  INTERVOX_IO_TEST_DATA="${CMAKE_CURRENT_SOURCE_DIR}/io/data")
find_package(octomap QUIET)
if(octomap_FOUND)
  target_include_directories(${suite_target} SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
  target_link_libraries(${suite_target} PRIVATE ${OCTOMAP_LIBRARIES})
  target_compile_definitions(${suite_target} PRIVATE INTERVOX_HAVE_OCTOMAP=1)
endif()
target_compile_definitions(${suite_target} PRIVATE INTERVOX_TEST_DATA="${PROJECT_SOURCE_DIR}/tests/data")
