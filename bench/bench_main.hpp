#pragma once
// The main() of every Google Benchmark program in bench/: the vector walks switched on, and
// --smoke understood (the CTest smoke run: every benchmark once at the least time, without the
// side-by-side comparisons some programs print before their benchmarks).
#include <intervox/raycast/vector_walks.hpp>

#include <benchmark/benchmark.h>

#include <cstring>
#include <functional>

namespace bench {

/// True if argv holds "--smoke" (for a main() that registers lighter rows in a smoke run before
/// calling run_main(), which removes the flag).
inline bool has_smoke_flag(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::strcmp(argv[i], "--smoke") == 0) return true;
  return false;
}

/// Removes every "--smoke" from argv; true if there was one.
inline bool take_smoke_flag(int& argc, char** argv) {
  bool smoke = false;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--smoke") == 0) {
      smoke = true;
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
  return smoke;
}

/// Runs the registered benchmarks with Google Benchmark's options from argv; \p comparisons (if
/// given) runs first, except in a smoke run. Returns main()'s exit code.
inline int run_main(int argc, char** argv, const std::function<void()>& comparisons = {}) {
  intervox::use_vector_walks();
  const bool smoke = take_smoke_flag(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (comparisons && !smoke) comparisons();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace bench
