# The experiment pipeline tests include examples/experiments/sweep.hpp (and examples/common/policies.hpp)
# and link the runs compiled once (examples/experiments/runs.cmake).
include("${PROJECT_SOURCE_DIR}/examples/experiments/runs.cmake")
target_link_libraries(${suite_target} PRIVATE intervox_experiment_runs)
target_compile_definitions(${suite_target} PRIVATE INTERVOX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
