# cmake -DEXE=<suite executable> [-DSPEC=<Catch2 test spec>] -P check_test_names.cmake
# Fails if a test case name of the suite would not survive catch_discover_tests: a name with an
# unbalanced '[' or ']' merges with the names after it in a CMake list, and a name with a ';' is
# split in two; either way a CTest test then matches no case (and passes, running nothing).
cmake_minimum_required(VERSION 3.20)  # list() keeps empty elements (CMP0007)
execute_process(COMMAND "${EXE}" ${SPEC} --list-test-names-only OUTPUT_VARIABLE out RESULT_VARIABLE rc)
string(REGEX MATCHALL "\n" newlines "${out}")
list(LENGTH newlines lines)
string(REPLACE "\n" ";" names "${out}")
list(LENGTH names listed)
math(EXPR listed "${listed} - 1")  # the list after the last newline is empty
if(NOT listed EQUAL lines)
  message(FATAL_ERROR "${EXE}: ${lines} test cases, but CMake splits their names into ${listed}: a name holds an "
                      "unbalanced '[' or ']', or a ';' (rename it; docs/testing.md)")
endif()
message(STATUS "${EXE}: ${lines} test case names, each its own CTest test")
