#pragma once
// Shared by the typed tests of every folder: the one list of grid configurations they run over
// (INTERVOX_TEST_GRIDS), the bounded sparse configuration (a SparseStorage grid constructed with
// Bounds, a distinct case for insertion, planning and files) and a guard that lets a test split
// work into more threads than the machine has.
#include <intervox/core/parallel.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

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

namespace iv = intervox;

// The grid configurations of every typed test: each update policy (every state rule of the interval
// update among them), each utility, each storage (sparse, bounded sparse, dense), in 12 types. The
// full product (7 updates x 3 utilities x 3 storages) would triple the tests' compile time for
// little: storage and policy code do not depend on each other beyond the cell type.
using BayesSparse = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::SparseStorage>;
using BayesDense = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::DenseStorage>;
using BayesBoundedSparse = BoundedSparse<BayesSparse>;
using LowerSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy, iv::SparseStorage>;
using MeanDense = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::Entropy, iv::DenseStorage>;
using MeanBoundedSparse =
    BoundedSparse<iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::SparseStorage>>;
using UpperSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::Entropy, iv::SparseStorage>;
using UpperDense = iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::MaxEntropy, iv::DenseStorage>;
using CompactSparse = iv::VoxelGrid<iv::CompactIntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::SparseStorage>;
using CompactBoundedSparse =
    BoundedSparse<iv::VoxelGrid<iv::CompactIntervalUpdate<iv::LowerState>, iv::Entropy, iv::SparseStorage>>;
using DirichletDense =
    iv::VoxelGrid<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::TotalUncertainty, iv::DenseStorage>;
using BeliefSparse = iv::VoxelGrid<iv::DempsterShaferUpdate<iv::UpperState>, iv::MaxEntropy, iv::SparseStorage>;

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

/// The grid types of every typed test (TEMPLATE_TEST_CASE(..., INTERVOX_TEST_GRIDS)).
#define INTERVOX_TEST_GRIDS                                                                                          \
  test::BayesSparse, test::BayesDense, test::BayesBoundedSparse, test::LowerSparse, test::MeanDense,                 \
      test::MeanBoundedSparse, test::UpperSparse, test::UpperDense, test::CompactSparse, test::CompactBoundedSparse, \
      test::DirichletDense, test::BeliefSparse
