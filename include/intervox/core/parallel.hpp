#pragma once
/// \file
/// The one place Intervox starts threads: ray insertion, candidate evaluation and the simulator
/// split their work with run_on_threads(). Results never depend on the number of threads; each
/// caller partitions its work deterministically.
/// Thread safety: run_on_threads may be called from any thread; `f` must be safe to run
/// concurrently for distinct t.

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace intervox {

/// A thread count as the options take it: 0 means every hardware thread (at least 1).
inline unsigned resolve_threads(unsigned threads) noexcept {
  return threads != 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
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
