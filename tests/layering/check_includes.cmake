# Fails if any header of a layer includes, directly or through other headers, a file it must not:
#  - the planning layer (intervox/plan/) decides from the map alone: no simulator (intervox/sim/)
#    and no PNG writer (intervox/io/png.hpp, png.h), so it needs no libpng;
#  - the grid and ray-casting layers (intervox/grid/, intervox/raycast/) include no update policy
#    (only intervox/update/concepts.hpp): a program includes the one policy it uses
#    (grid/named_grids.hpp, which names the common configurations, includes them all on purpose).
#
# Usage: cmake -DCXX=<compiler> -DINCLUDE=<dir with intervox/> -DEXTRA_INCLUDES=<dir;dir>
#              -DLAYERS=<layer,layer...> -DFORBIDDEN=<regex> [-DALLOWED=<regex>] [-DEXEMPT=<regex>]
#              -P check_includes.cmake
# FORBIDDEN matches the included paths that break the rule, ALLOWED those among them that do not
# after all, EXEMPT the layer headers not checked. Each header is preprocessed on its own (-M
# lists every file it pulls in).
if(NOT CXX OR NOT INCLUDE OR NOT LAYERS OR NOT FORBIDDEN)
  message(FATAL_ERROR "check_includes: pass -DCXX=... -DINCLUDE=... -DLAYERS=... -DFORBIDDEN=...")
endif()
string(REPLACE "," ";" LAYERS "${LAYERS}")
set(headers "")
foreach(layer IN LISTS LAYERS)
  file(GLOB layer_headers "${INCLUDE}/intervox/${layer}/*.hpp")
  list(APPEND headers ${layer_headers})
endforeach()
if(EXEMPT)
  list(FILTER headers EXCLUDE REGEX "${EXEMPT}")
endif()
if(NOT headers)
  message(FATAL_ERROR "check_includes: no header under ${INCLUDE}/intervox/{${LAYERS}}")
endif()
set(flags -std=c++20 -x c++ -M "-I${INCLUDE}")
foreach(dir IN LISTS EXTRA_INCLUDES)
  list(APPEND flags "-I${dir}")
endforeach()
set(bad "")
foreach(h IN LISTS headers)
  execute_process(COMMAND ${CXX} ${flags} "${h}" RESULT_VARIABLE rc OUTPUT_VARIABLE deps ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "check_includes: cannot preprocess ${h}:\n${err}")
  endif()
  string(REGEX MATCHALL "[^ \\\n]*(${FORBIDDEN})[^ \\\n]*" hits "${deps}")
  if(hits AND ALLOWED)
    list(FILTER hits EXCLUDE REGEX "${ALLOWED}")
  endif()
  if(hits)
    list(REMOVE_DUPLICATES hits)
    string(REPLACE ";" "\n    " hits "${hits}")
    string(APPEND bad "  ${h} pulls in:\n    ${hits}\n")
  endif()
endforeach()
if(bad)
  message(FATAL_ERROR "headers of intervox/{${LAYERS}} include what their layer must not (${FORBIDDEN}):\n${bad}")
endif()
list(LENGTH headers n)
message(STATUS "check_includes: ${n} headers under intervox/{${LAYERS}} include nothing matching ${FORBIDDEN}")
