#pragma once
/// \file
/// The one place Intervox starts threads: ray insertion, candidate evaluation and the simulator
/// split their work with run_on_threads(). Results never depend on the number of threads; each
/// caller partitions its work deterministically. Every thread count a user passes goes through
/// resolve_threads(): 0 means all hardware threads, larger counts are capped at the hardware
/// concurrency.
/// Thread safety: run_on_threads may be called from any thread; `f` must be safe to run
/// concurrently for distinct t.

#include <algorithm>
#include <atomic>
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

}  // namespace intervox
