# Compiles one fuzz target's source with clang (the compiler of the libFuzzer build,
# -DINTERVOX_BUILD_FUZZERS=ON) without linking: -fsyntax-only, C++20, the project's warnings as
# errors. The corpus replay (fuzz_corpus.*) compiles the same sources with the test build's
# compiler, usually g++; this keeps them, and every header they include, compiling with the
# packaged clang (Debian's clang 14), which rejects code that g++ and newer clangs accept (e.g. a
# lambda capturing a structured binding, C++20 only from clang 16).
#
# Usage: cmake -DCLANG=<clang++> -DSOURCE=<fuzz_x.cpp> -DINCLUDE=<the project's include/>
#              "-DSYSTEM_INCLUDES=<dir;dir>" -P clang_syntax.cmake
if(NOT CLANG OR NOT SOURCE OR NOT INCLUDE)
  message(FATAL_ERROR "clang_syntax: pass -DCLANG=... -DSOURCE=... -DINCLUDE=...")
endif()
set(flags -std=c++20 -fsyntax-only -Wall -Wextra -Wpedantic -Werror "-I${INCLUDE}")
foreach(dir IN LISTS SYSTEM_INCLUDES)
  # (the compiler's own folders stay where they are: an -isystem /usr/include breaks the C++
  # library's #include_next of the C headers)
  if(NOT dir MATCHES "^/usr(/local)?/include/?$")
    list(APPEND flags "-isystem" "${dir}")
  endif()
endforeach()
execute_process(COMMAND "${CLANG}" ${flags} "${SOURCE}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "clang_syntax: ${CLANG} cannot compile ${SOURCE}:\n${out}${err}")
endif()
message(STATUS "clang_syntax: ${SOURCE} compiles with ${CLANG}")
