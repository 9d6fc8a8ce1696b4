#pragma once
// A harness check that failed: says which on stderr, then aborts (libFuzzer reports a deadly
// signal and saves the input; the corpus replay fails with the message).
#include <cstdio>
#include <cstdlib>

[[noreturn]] inline void fuzz_check_failed(const char* what) {
  std::fprintf(stderr, "fuzz check failed: %s\n", what);
  std::fflush(stderr);
  std::abort();
}
