# view tests: the viewer page (view/html_view.hpp) and its run file (view/view_scene_json.hpp); the
# page in a real browser: view.browser renders it with headless Chromium (skipped, exit code 77,
# only where Chromium is absent).
find_package(nlohmann_json 3 REQUIRED)
target_link_libraries(${suite_target} PRIVATE nlohmann_json::nlohmann_json)
if(TARGET intervox::png)
  add_executable(intervox_view_browser_check "${CMAKE_CURRENT_SOURCE_DIR}/view/browser/browser_check.cpp")
  target_link_libraries(intervox_view_browser_check PRIVATE intervox::png)
  intervox_own_target(intervox_view_browser_check)
  find_program(INTERVOX_CHROMIUM NAMES chromium chromium-browser google-chrome)
  if(NOT INTERVOX_CHROMIUM)
    set(INTERVOX_CHROMIUM "")
  endif()
  add_test(NAME view.browser COMMAND intervox_view_browser_check "${INTERVOX_CHROMIUM}")
  set_tests_properties(view.browser PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 180
    WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}")
endif()
