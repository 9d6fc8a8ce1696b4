# Runs one example program with the arguments after "--" and checks how it ends (CTest, see
# examples/CMakeLists.txt):
#   cmake -DPROGRAM=<exe> -DEXPECT=error|ok -DWORKDIR=<folder> -P check_cli.cmake -- <arguments>
# The program runs in WORKDIR (created, with a regular file "afile" in it for paths below a file).
# EXPECT=error: the program must exit with a non-zero exit code (a crash or a signal is a failure)
# and print "<name>: error: ..." on stderr. EXPECT=ok: it must exit with 0.
# The script prints the exit code and the program's output, for the test's PASS_REGULAR_EXPRESSION
# on the message, and "cli-check FAILED" (the test's FAIL_REGULAR_EXPRESSION) when the exit is wrong.
set(args)
set(after_dashes FALSE)
math(EXPR last "${CMAKE_ARGC} - 1")
foreach(i RANGE ${last})
  if(after_dashes)
    list(APPEND args "${CMAKE_ARGV${i}}")
  elseif(CMAKE_ARGV${i} STREQUAL "--")
    set(after_dashes TRUE)
  endif()
endforeach()

file(REMOVE_RECURSE "${WORKDIR}")
file(MAKE_DIRECTORY "${WORKDIR}")
file(WRITE "${WORKDIR}/afile" "a regular file\n")
execute_process(COMMAND "${PROGRAM}" ${args} WORKING_DIRECTORY "${WORKDIR}"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
get_filename_component(name "${PROGRAM}" NAME_WE)
message("${name} ${args}\nexit code ${code}\n--- stdout\n${out}--- stderr\n${err}---")
if(NOT code MATCHES "^[0-9]+$")
  message("cli-check FAILED: the program did not exit normally (${code})")
elseif(EXPECT STREQUAL "error")
  if(code EQUAL 0)
    message("cli-check FAILED: exit code 0 on bad input")
  elseif(NOT err MATCHES "(^|\n)${name}: error: ")
    message("cli-check FAILED: no '${name}: error: ...' line on stderr")
  endif()
elseif(NOT code EQUAL 0)
  message("cli-check FAILED: exit code ${code} on good input")
endif()
