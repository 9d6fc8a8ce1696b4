# The raycast suite compares ray insertion with OctoMap voxel by voxel (Debian liboctomap-dev).
find_package(octomap REQUIRED)
target_include_directories(${suite_target} SYSTEM PRIVATE ${OCTOMAP_INCLUDE_DIRS})
target_link_libraries(${suite_target} PRIVATE ${OCTOMAP_LIBRARIES})
