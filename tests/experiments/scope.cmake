# The experiment pipeline runs whole episodes and sweeps through the 20 run configurations of
# examples/experiments/run_one.cpp: built and run in the Release build only (with the tests'
# _GLIBCXX_ASSERTIONS), never under the sanitizers (docs/testing.md, "What each stage runs").
set(intervox_suite_release_only ON)
