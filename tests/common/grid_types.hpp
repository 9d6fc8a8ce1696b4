#pragma once
// Shared by the typed tests of every folder: the bounded sparse configuration (a SparseStorage
// grid constructed with Bounds, a distinct case for insertion, planning and files) and a guard
// that lets a test split work into more threads than the machine has.
#include <intervox/core/parallel.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <utility>

namespace test {

/// A sparse grid G constructed with bounds. The same storage as G; a type of its own only so
/// that typed tests can list "bounded sparse" beside "sparse" and "dense".
template <class G>
struct BoundedSparse : G {
  static_assert(!G::StorageType::kBounded, "BoundedSparse wraps a sparse grid");
  using G::G;
  BoundedSparse(G&& g) : G(std::move(g)) {}  // NOLINT: implicit on purpose (loaders return G)
};

/// True if typed tests construct grid type G with bounds.
template <class G>
inline constexpr bool kConstructBounded = G::StorageType::kBounded;
template <class G>
inline constexpr bool kConstructBounded<BoundedSparse<G>> = true;

/// A grid of type G at \p resolution: with \p bounds if kConstructBounded<G>, unbounded otherwise.
// noinline: GCC 12 reports a false -Wdangling-pointer when this is inlined at -O2.
template <class G>
[[gnu::noinline]] G make_grid_for(double resolution, const intervox::Bounds& bounds) {
  if constexpr (kConstructBounded<G>) {
    return G(resolution, bounds);
  } else {
    return G(resolution);
  }
}

/// While alive, Intervox caps thread counts at \p n instead of the hardware concurrency, so a
/// test can check that splitting work into n threads changes no result on any machine.
class ThreadCap {
 public:
  explicit ThreadCap(unsigned n) : old_(intervox::detail::thread_cap_override.exchange(n)) {}
  ~ThreadCap() { intervox::detail::thread_cap_override.store(old_); }
  ThreadCap(const ThreadCap&) = delete;
  ThreadCap& operator=(const ThreadCap&) = delete;

 private:
  unsigned old_;
};

}  // namespace test
