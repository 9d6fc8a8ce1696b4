#pragma once
/// \file
/// The one place Intervox starts threads: ray insertion, candidate evaluation and the simulator
/// split their work with run_on_threads() or one of the two loops built on it, parallel_for()
/// (index i on thread i % threads, for items of uneven cost such as candidate views) and
/// parallel_for_chunks() (contiguous chunks, for many cheap items such as simulated beams).
/// Results never depend on the number of threads; each caller partitions its work
/// deterministically and writes item i's result to its own slot. Every thread count a user passes goes through
/// resolve_threads(): 0 means all hardware threads, larger counts are capped at the hardware
/// concurrency.
/// Thread safety: run_on_threads may be called from any thread; `f` must be safe to run
/// concurrently for distinct t.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace intervox {

namespace detail {
/// Test hook: when non-zero, replaces std::thread::hardware_concurrency() as the thread cap, so
/// that tests can exercise splits into more threads than the machine has. Not for users.
inline std::atomic<unsigned> thread_cap_override{0};
}  // namespace detail

/// The most threads any Intervox call starts: std::thread::hardware_concurrency() (at least 1).
/// More threads than hardware threads only add scratch memory and scheduling cost.
inline unsigned max_threads() noexcept {
  const unsigned o = detail::thread_cap_override.load(std::memory_order_relaxed);
  return o != 0 ? o : std::max(1u, std::thread::hardware_concurrency());
}

/// A thread count as every option that takes one reads it: 0 means every hardware thread, and
/// any count is capped at max_threads() (the hardware concurrency). Results never depend on it.
inline unsigned resolve_threads(unsigned threads) noexcept {
  const unsigned cap = max_threads();
  return threads == 0 ? cap : std::min(threads, cap);
}

/// Runs `f(t)` for every t in [0, n) on n threads, t = 0 on the calling thread, and waits for all.
/// The first exception thrown by any `f(t)` is rethrown after every thread joined (never
/// std::terminate). n <= 1 runs f(0) on the calling thread.
/// \tparam F callable as f(unsigned)
template <class F>
void run_on_threads(unsigned n, F&& f) {
  if (n <= 1) {
    f(0u);
    return;
  }
  std::vector<std::exception_ptr> errors(n);
  std::vector<std::thread> pool;
  pool.reserve(n - 1);
  for (unsigned t = 1; t < n; ++t) {
    pool.emplace_back([&, t] {
      try {
        f(t);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    });
  }
  try {
    f(0u);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (auto& th : pool) th.join();
  for (auto& e : errors)
    if (e) std::rethrow_exception(e);
}

/// Runs `f(i)` once for every index i in [0, n) on up to resolve_threads(\p threads) threads
/// (never more than n), interleaved: index i runs on thread i % threads, so items of uneven cost
/// (e.g. candidate views) spread evenly. Waits for all; the first exception thrown by any `f(i)`
/// is rethrown on the calling thread after every thread joined (an index after a failed one on
/// the same thread does not run). n = 0 calls nothing.
/// \tparam F callable as f(std::size_t)
/// Thread safety: `f` must be safe to run concurrently for distinct i; which thread runs an index
/// depends on the thread count, so `f(i)` must not depend on it.
template <class F>
void parallel_for(std::size_t n, unsigned threads, F&& f) {
  if (n == 0) return;
  const auto used = static_cast<unsigned>(std::min<std::size_t>(resolve_threads(threads), n));
  run_on_threads(used, [&](unsigned t) {
    for (std::size_t i = t; i < n; i += used) f(i);
  });
}

/// Runs `f(begin, end)` over [0, n) split into at most resolve_threads(\p threads) contiguous,
/// non-empty chunks, one per thread, each at least \p min_chunk long (so that small loops stay on
/// the calling thread: fewer than 2 * min_chunk indices use one thread). Every index lies in
/// exactly one chunk. Waits for all; the first exception thrown by any call is rethrown on the
/// calling thread after every thread joined. n = 0 calls nothing.
/// \tparam F callable as f(std::size_t begin, std::size_t end), end exclusive
/// Thread safety: `f` must be safe to run concurrently for disjoint ranges; the split depends on
/// the thread count, so results must not.
template <class F>
void parallel_for_chunks(std::size_t n, unsigned threads, F&& f, std::size_t min_chunk = 256) {
  if (n == 0) return;
  const auto used = static_cast<unsigned>(std::min<std::size_t>(
      resolve_threads(threads), std::max<std::size_t>(1, n / std::max<std::size_t>(1, min_chunk))));
  const std::size_t chunk = (n + used - 1) / used;
  run_on_threads(used, [&](unsigned t) {
    const std::size_t b = std::min(n, t * chunk), e = std::min(n, b + chunk);
    if (b < e) f(b, e);
  });
}

}  // namespace intervox
