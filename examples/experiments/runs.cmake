# intervox_experiment_runs: run_one.cpp, the translation unit that instantiates every offered run
# configuration, compiled once and linked by the experiments program and the experiments tests
# (included from both; whichever comes first defines it). Needs nlohmann-json and intervox::png.
if(NOT TARGET intervox_experiment_runs)
  find_package(nlohmann_json 3 REQUIRED)
  add_library(intervox_experiment_runs STATIC "${CMAKE_CURRENT_LIST_DIR}/run_one.cpp")
  target_include_directories(intervox_experiment_runs PUBLIC "${CMAKE_CURRENT_LIST_DIR}" "${CMAKE_CURRENT_LIST_DIR}/..")
  target_link_libraries(intervox_experiment_runs PUBLIC nlohmann_json::nlohmann_json intervox::png)
  intervox_own_target(intervox_experiment_runs)
  # -O1 under the sanitizers, as the test suites (tests/CMakeLists.txt).
  target_compile_options(intervox_experiment_runs PRIVATE
    $<$<OR:$<BOOL:${INTERVOX_SANITIZE}>,$<BOOL:${INTERVOX_SANITIZE_THREAD}>>:-O1>)
endif()
