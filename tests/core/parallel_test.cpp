#include <catch2/catch.hpp>
#include <intervox/core/parallel.hpp>

#include <algorithm>
#include <atomic>
#include <thread>
#include <stdexcept>
#include <vector>

TEST_CASE("work on threads runs every index once and rethrows the first error on the caller",
          "[core][parallel][threaded]") {
  for (unsigned n : {0u, 1u, 2u, 5u}) {
    std::vector<std::atomic<int>> runs(std::max(1u, n));
    intervox::run_on_threads(n, [&](unsigned t) { ++runs[t]; });
    for (auto& r : runs) CHECK(r == 1);
  }
  std::atomic<int> finished{0};
  CHECK_THROWS_AS(intervox::run_on_threads(4,
                                           [&](unsigned t) {
                                             if (t == 2) throw std::runtime_error("worker failed");
                                             ++finished;
                                           }),
                  std::runtime_error);
  CHECK(finished == 3);  // the others ran to the end and were joined
  CHECK(intervox::resolve_threads(0) >= 1);
}

TEST_CASE("a thread count is capped at the hardware concurrency, and 0 means all of it", "[core][parallel][threaded]") {
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  CHECK(intervox::max_threads() == hw);
  CHECK(intervox::resolve_threads(0) == hw);
  CHECK(intervox::resolve_threads(1) == 1);
  CHECK(intervox::resolve_threads(hw) == hw);
  CHECK(intervox::resolve_threads(1000) == hw);
  CHECK(intervox::resolve_threads(~0u) == hw);
}
