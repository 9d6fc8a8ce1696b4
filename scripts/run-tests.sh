#!/usr/bin/env bash
# The whole test suite on a fresh Debian machine: installs missing packages, then runs every test
# case once, in two stages that share the work (docs/testing.md, "What each stage runs"):
#  1. Release (build/): builds everything (examples, benchmarks, Python) and runs what needs an
#     optimised build: the long episodes and sweeps ([slow], with _GLIBCXX_ASSERTIONS), the
#     experiments suite, the benchmarks' smoke runs, the command-line, Python, consumer,
#     compile-fail and layering checks;
#  2. ASan/UBSan (build-asan/): every other test case, with _GLIBCXX_ASSERTIONS, and the fuzz
#     corpora.
# Options run one stage alone: `--release` builds and runs every test case in Release (no
# sanitizer, as fast as the tests get), `--sanitize` stage 2 alone, `--tsan` the threaded test
# cases under ThreadSanitizer (build-tsan/).
# The sanitizer builds carry no debug information (-g0: a third less compile time; reports still
# name functions); set INTERVOX_DEBUG_FLAGS=-g for file and line numbers in their reports.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/setup.sh
intervox_install_missing

jobs="$(nproc 2>/dev/null || echo 2)"
debug_flags="${INTERVOX_DEBUG_FLAGS:--g0}"
# Every stage registers each Catch2 test case as a CTest test of its own and runs them on every
# core; what a sanitizer stage builds and runs is chosen by tests/CMakeLists.txt (its "test scope":
# docs/testing.md, "What each stage runs"). Build folders: $INTERVOX_BUILD_DIR (build),
# $INTERVOX_ASAN_BUILD_DIR (build-asan), $INTERVOX_TSAN_BUILD_DIR (build-tsan).

# intervox_sanitize_stage: ASan/UBSan over every test case but the long episodes and sweeps
# ([slow]; the Release stage runs them with _GLIBCXX_ASSERTIONS).
intervox_sanitize_stage() {
  local dir="${INTERVOX_ASAN_BUILD_DIR:-build-asan}"
  cmake -S . -B "$dir" $(intervox_generator "$dir") -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="$debug_flags" \
    -DINTERVOX_SANITIZE=ON -DINTERVOX_TEST_SCOPE=memory -DINTERVOX_BUILD_TESTS=ON -DINTERVOX_BUILD_BENCHMARKS=OFF \
    -DINTERVOX_BUILD_EXAMPLES=OFF
  cmake --build "$dir" -j"$jobs"
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
}

# intervox_release_stage SCOPE: everything built in Release; the test cases of SCOPE run.
intervox_release_stage() {
  local dir="${INTERVOX_BUILD_DIR:-build}"
  INTERVOX_BUILD_DIR="$dir" intervox_build -DINTERVOX_TEST_SCOPE="$1"
  ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
}

case "${1:-}" in
  --tsan)
    # ThreadSanitizer over the test cases tagged [threaded] (raycast, explain, plan, sim, core).
    dir="${INTERVOX_TSAN_BUILD_DIR:-build-tsan}"
    cmake -S . -B "$dir" $(intervox_generator "$dir") -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="$debug_flags" \
      -DINTERVOX_SANITIZE_THREAD=ON -DINTERVOX_TEST_SCOPE=threaded -DINTERVOX_BUILD_TESTS=ON \
      -DINTERVOX_BUILD_BENCHMARKS=OFF -DINTERVOX_BUILD_EXAMPLES=OFF
    cmake --build "$dir" -j"$jobs"
    TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1" \
      ctest --test-dir "$dir" --output-on-failure --no-tests=error -j"$jobs"
    ;;
  --sanitize)
    intervox_sanitize_stage
    ;;
  --release)
    intervox_release_stage all
    ;;
  "")
    start=$(date +%s)
    intervox_release_stage slow
    echo "intervox: Release stage passed after $(( $(date +%s) - start )) s; now the ASan/UBSan stage"
    intervox_sanitize_stage
    echo "intervox: ASan/UBSan stage passed; both stages took $(( $(date +%s) - start )) s"
    ;;
  *)
    echo "run-tests.sh: unknown option '$1' (expected nothing, --release, --sanitize or --tsan)" >&2
    exit 2
    ;;
esac
