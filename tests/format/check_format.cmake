# Fails if a C++ file of the tree is not formatted as .clang-format says (one formatter for the
# whole tree: clang-format 14, Debian's; other versions format some constructs differently, so
# the check runs only that one, and prints "check_format: skipped" without it, which CTest reads
# as a skip: SKIP_REGULAR_EXPRESSION in tests/CMakeLists.txt).
#
# Usage: cmake -DCLANG_FORMAT=<clang-format-14> -DROOT=<tree> [-DDIRS=<dir;dir>] [-DEXCLUDE=<regex>]
#              -P check_format.cmake
# DIRS are the folders (relative to ROOT) searched for *.hpp, *.cpp and *.h; by default every folder
# with C++ of ours. Files matching EXCLUDE are left out; by default tests/format/bad/ (the planted
# file of the *_detects_* test).
# To format the tree: clang-format-14 -i $(git ls-files '*.hpp' '*.cpp' '*.h' | grep -v '^tests/format/bad/')
if(NOT ROOT)
  message(FATAL_ERROR "check_format: pass -DROOT=<tree>")
endif()
if(NOT CLANG_FORMAT OR NOT EXISTS "${CLANG_FORMAT}")
  message(STATUS "check_format: skipped, clang-format-14 not found (scripts/setup.sh installs it)")
  return()
endif()
if(NOT DIRS)
  set(DIRS include tests examples bench python ros scripts)
endif()
set(files "")
foreach(dir IN LISTS DIRS)
  file(GLOB_RECURSE found "${ROOT}/${dir}/*.hpp" "${ROOT}/${dir}/*.cpp" "${ROOT}/${dir}/*.h")
  list(APPEND files ${found})
endforeach()
if(NOT DEFINED EXCLUDE)
  set(EXCLUDE "/tests/format/bad/")
endif()
if(EXCLUDE)
  list(FILTER files EXCLUDE REGEX "${EXCLUDE}")
endif()
if(NOT files)
  message(FATAL_ERROR "check_format: no C++ file under ${ROOT}/{${DIRS}}")
endif()
list(SORT files)
execute_process(COMMAND "${CLANG_FORMAT}" --dry-run --Werror --style=file ${files}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  string(REGEX MATCHALL "[^\n]*: error: code should be clang-formatted[^\n]*" hits "${err}")
  set(names "")
  foreach(h IN LISTS hits)
    string(REGEX REPLACE ":[0-9]+:[0-9]+: error:.*" "" f "${h}")
    list(APPEND names "${f}")
  endforeach()
  list(REMOVE_DUPLICATES names)
  list(LENGTH names n)
  string(REPLACE ";" "\n  " names "${names}")
  message(FATAL_ERROR "check_format: ${n} files are not formatted as .clang-format says (run clang-format-14 -i on them):\n  ${names}")
endif()
list(LENGTH files n)
message(STATUS "check_format: ${n} files formatted as .clang-format says")
