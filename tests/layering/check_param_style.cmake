# Fails if a header under include/intervox/ validates a parameter by hand, i.e. contains
# `throw InvalidArgument(`: parameters are checked one way, with ParamCheck
# (intervox/core/validate.hpp), whose fail() builds the "<where>: <what>" message. Only
# core/validate.hpp (ParamCheck itself) and core/error.hpp (the exception) may throw it by hand.
#
# Usage: cmake -DINCLUDE=<dir with intervox/> [-DEXEMPT=<path;path>] -P check_param_style.cmake
# EXEMPT lists headers (relative to INCLUDE/intervox/) not checked (none by default: every header
# follows the rule). Each offending line is reported as <file>:<line>: <text>.
if(NOT INCLUDE)
  message(FATAL_ERROR "check_param_style: pass -DINCLUDE=<dir with intervox/>")
endif()
get_filename_component(INCLUDE "${INCLUDE}" ABSOLUTE)

if(NOT DEFINED EXEMPT)
  set(EXEMPT "")
endif()

file(GLOB_RECURSE headers RELATIVE "${INCLUDE}/intervox" "${INCLUDE}/intervox/*.hpp")
if(NOT headers)
  message(FATAL_ERROR "check_param_style: no header under ${INCLUDE}/intervox/")
endif()
list(REMOVE_ITEM headers core/validate.hpp core/error.hpp ${EXEMPT})
list(SORT headers)
set(bad "")
set(count 0)
foreach(h IN LISTS headers)
  file(READ "${INCLUDE}/intervox/${h}" text)
  if(NOT text MATCHES "throw InvalidArgument\\(")
    continue()
  endif()
  # Line numbers: split on newlines (escape ';' and brackets so the list keeps every line).
  string(REPLACE ";" "\\;" text "${text}")
  string(REPLACE "[" "<" text "${text}")
  string(REPLACE "]" ">" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(n 0)
  foreach(line IN LISTS text)
    math(EXPR n "${n} + 1")
    if(line MATCHES "throw InvalidArgument\\(")
      string(STRIP "${line}" shown)
      string(APPEND bad "  include/intervox/${h}:${n}: ${shown}\n")
      math(EXPR count "${count} + 1")
    endif()
  endforeach()
endforeach()
if(bad)
  message(FATAL_ERROR "check_param_style: ${count} hand-written `throw InvalidArgument(` in headers; "
    "check parameters with ParamCheck (intervox/core/validate.hpp: its named checks, or check.fail(\"...\")):\n${bad}")
endif()
list(LENGTH headers n)
message(STATUS "check_param_style: ${n} headers under intervox/ throw no InvalidArgument by hand")
