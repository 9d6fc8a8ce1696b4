#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/core/parallel.hpp>

#include <atomic>
#include <cstddef>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace {
// Counts how often each index of [0, n) was visited; written concurrently.
std::vector<int> counts_of(const std::vector<std::atomic<int>>& runs) {
  std::vector<int> out;
  for (const auto& r : runs) out.push_back(r.load());
  return out;
}
}  // namespace

TEST_CASE("parallel_for runs every index exactly once on 1 to 5 threads, interleaved", "[core][parallel][threaded]") {
  for (unsigned cap = 1; cap <= 5; ++cap) {
    const test::ThreadCap capped(cap);
    for (std::size_t n : {std::size_t{1}, std::size_t{3}, std::size_t{7}, std::size_t{1000}}) {
      std::vector<std::atomic<int>> runs(n);
      std::mutex m;
      std::vector<std::set<std::thread::id>> owner(cap);  // thread ids seen per residue i % threads
      const auto used = std::min<std::size_t>(cap, n);
      intervox::parallel_for(n, 0, [&](std::size_t i) {
        ++runs[i];
        const std::lock_guard<std::mutex> lock(m);
        owner[i % used].insert(std::this_thread::get_id());
      });
      CHECK(counts_of(runs) == std::vector<int>(n, 1));
      // Interleaved: all indices with the same residue ran on one thread, and the residues on distinct threads.
      std::set<std::thread::id> all;
      for (std::size_t r = 0; r < used; ++r) {
        CHECK(owner[r].size() == 1);
        all.insert(owner[r].begin(), owner[r].end());
      }
      CHECK(all.size() == used);
    }
  }
}

TEST_CASE("parallel_for_chunks covers the indices 0 to n - 1 with disjoint non-empty chunks on 1 to 5 threads",
          "[core][parallel][threaded]") {
  for (unsigned cap = 1; cap <= 5; ++cap) {
    const test::ThreadCap capped(cap);
    for (std::size_t n : {std::size_t{1}, std::size_t{255}, std::size_t{513}, std::size_t{5000}}) {
      std::vector<std::atomic<int>> runs(n);
      std::atomic<unsigned> calls{0};
      std::atomic<bool> empty_chunk{false};
      intervox::parallel_for_chunks(n, 0, [&](std::size_t b, std::size_t e) {
        ++calls;
        if (b >= e) empty_chunk = true;
        for (std::size_t i = b; i < e; ++i) ++runs[i];
      });
      CHECK(counts_of(runs) == std::vector<int>(n, 1));
      CHECK_FALSE(empty_chunk);
      // One chunk per thread, at least 256 indices each: n / 256 threads at most.
      CHECK(calls == std::min<std::size_t>(cap, std::max<std::size_t>(1, n / 256)));
    }
    // A smaller grain splits small loops too.
    std::vector<std::atomic<int>> runs(10);
    std::atomic<unsigned> calls{0};
    intervox::parallel_for_chunks(
        10, 0,
        [&](std::size_t b, std::size_t e) {
          ++calls;
          for (std::size_t i = b; i < e; ++i) ++runs[i];
        },
        1);
    CHECK(counts_of(runs) == std::vector<int>(10, 1));
    CHECK(calls == std::min(cap, 10u));
  }
}

TEST_CASE("the parallel loops call nothing for n = 0", "[core][parallel][threaded]") {
  const test::ThreadCap capped(4);
  int calls = 0;
  intervox::parallel_for(0, 0, [&](std::size_t) { ++calls; });
  intervox::parallel_for_chunks(0, 0, [&](std::size_t, std::size_t) { ++calls; });
  intervox::parallel_for_chunks(
      0, 0, [&](std::size_t, std::size_t) { ++calls; }, 1);
  CHECK(calls == 0);
}

TEST_CASE("the parallel loops rethrow a worker's exception on the caller after every thread joined",
          "[core][parallel][threaded]") {
  for (unsigned cap = 1; cap <= 5; ++cap) {
    const test::ThreadCap capped(cap);
    std::atomic<int> done{0};
    CHECK_THROWS_AS(intervox::parallel_for(50, 0,
                                           [&](std::size_t i) {
                                             if (i == 7) throw std::runtime_error("item 7 failed");
                                             ++done;
                                           }),
                    std::runtime_error);
    // Every other thread runs all its indices; the failing thread stops at 7.
    const int after = static_cast<int>((49 - 7) / cap);  // indices 7 + k * cap, k >= 1, below 50
    CHECK(done == 49 - after);
    std::atomic<int> chunks{0};
    CHECK_THROWS_WITH(intervox::parallel_for_chunks(1000, 0,
                                                    [&](std::size_t b, std::size_t e) {
                                                      ++chunks;
                                                      if (b <= 999 && 999 < e)
                                                        throw std::out_of_range("last chunk failed");
                                                    }),
                      "last chunk failed");
    CHECK(chunks == static_cast<int>(std::min(cap, 3u)));  // every chunk ran; the failing one rethrown
  }
}
