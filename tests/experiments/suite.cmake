# The experiment pipeline test includes examples/experiments/sweep.hpp (and examples/common/policies.hpp).
find_package(nlohmann_json 3 REQUIRED)
target_include_directories(${suite_target} PRIVATE "${PROJECT_SOURCE_DIR}/examples/experiments" "${PROJECT_SOURCE_DIR}/examples")
target_link_libraries(${suite_target} PRIVATE nlohmann_json::nlohmann_json intervox::png)
target_compile_definitions(${suite_target} PRIVATE INTERVOX_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
