# Corpus regression without libFuzzer (any compiler, also under INTERVOX_SANITIZE): every fuzz
# target's LLVMFuzzerTestOneInput is linked with corpus_replay.cpp, whose main() feeds it every
# file of the target's seed corpus; registered as the CTest test fuzz_corpus.<name>.
include("${CMAKE_CURRENT_LIST_DIR}/targets.cmake")
foreach(name IN LISTS INTERVOX_FUZZ_TARGETS)
  set(target intervox_fuzz_replay_${name})
  add_executable(${target} "${CMAKE_CURRENT_LIST_DIR}/corpus_replay.cpp" "${CMAKE_CURRENT_LIST_DIR}/fuzz_${name}.cpp")
  intervox_own_target(${target})
  intervox_fuzz_target_deps(${target} ${name})
  target_compile_definitions(${target} PRIVATE INTERVOX_CORPUS_REPLAY=1)
  target_compile_options(${target} PRIVATE $<IF:$<BOOL:${INTERVOX_SANITIZE}>,-Og,-O2>)
  add_test(NAME fuzz_corpus.${name}
    COMMAND ${target} "${PROJECT_SOURCE_DIR}/tests/io/data/fuzz/${INTERVOX_FUZZ_CORPUS_${name}}")
endforeach()
