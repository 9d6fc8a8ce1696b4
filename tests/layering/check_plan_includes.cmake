# Fails if any header under <include>/intervox/plan/ includes, directly or through other headers,
# the simulator (intervox/sim/) or the PNG writer (intervox/io/png.hpp, png.h): the planning layer
# decides from the map alone and needs no libpng.
#
# Usage: cmake -DCXX=<compiler> -DINCLUDE=<dir with intervox/> -DEXTRA_INCLUDES=<dir;dir>
#              -P check_plan_includes.cmake
# Each header is preprocessed on its own (-M lists every file it pulls in).
if(NOT CXX OR NOT INCLUDE)
  message(FATAL_ERROR "check_plan_includes: pass -DCXX=... -DINCLUDE=...")
endif()
file(GLOB headers "${INCLUDE}/intervox/plan/*.hpp")
if(NOT headers)
  message(FATAL_ERROR "check_plan_includes: no header under ${INCLUDE}/intervox/plan")
endif()
set(flags -std=c++20 -x c++ -M "-I${INCLUDE}")
foreach(dir IN LISTS EXTRA_INCLUDES)
  list(APPEND flags "-I${dir}")
endforeach()
set(bad "")
foreach(h IN LISTS headers)
  execute_process(COMMAND ${CXX} ${flags} "${h}" RESULT_VARIABLE rc OUTPUT_VARIABLE deps ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "check_plan_includes: cannot preprocess ${h}:\n${err}")
  endif()
  string(REGEX MATCHALL "[^ \\\n]*(intervox/sim/|intervox/io/png\\.hpp|/png\\.h)[^ \\\n]*" hits "${deps}")
  if(hits)
    list(REMOVE_DUPLICATES hits)
    string(REPLACE ";" "\n    " hits "${hits}")
    string(APPEND bad "  ${h} pulls in:\n    ${hits}\n")
  endif()
endforeach()
if(bad)
  message(FATAL_ERROR "headers of the planning layer include the simulator or libpng:\n${bad}")
endif()
list(LENGTH headers n)
message(STATUS "check_plan_includes: ${n} headers under intervox/plan include neither sim/ nor io/png")
