// Update throughput of every policy x storage: ns per voxel update for hits and misses, with
// sequential (x-fastest) and random access over a 256 x 256 x 64 voxel region (4.2 M voxels).
//
//   ./build/bench/bench_update --benchmark_counters_tabular=true
//
// Counters: items_per_second = voxel updates per second; ns_per_update = wall time per update.
#include <benchmark/benchmark.h>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

#include <cstdint>
#include <random>
#include <vector>
#include "bench_main.hpp"

namespace iv = intervox;

namespace {

constexpr int kNx = 256, kNy = 256, kNz = 64;
constexpr double kRes = 0.05;
const iv::Bounds kRegion{{0, 0, 0}, {kNx * kRes, kNy* kRes, kNz* kRes}};

enum class Access { Sequential, Random };

const std::vector<iv::Key>& keys(Access a) {
  static const std::vector<iv::Key> seq = [] {
    std::vector<iv::Key> k;
    k.reserve(std::size_t{kNx} * kNy * kNz);
    for (int z = 0; z < kNz; ++z)
      for (int y = 0; y < kNy; ++y)
        for (int x = 0; x < kNx; ++x) k.push_back({x, y, z});
    return k;
  }();
  static const std::vector<iv::Key> rnd = [] {
    std::vector<iv::Key> k(seq.size());
    std::mt19937_64 rng(12345);  // fixed seed: the same keys every run
    for (auto& key : k) key = {int(rng() % kNx), int(rng() % kNy), int(rng() % kNz)};
    return k;
  }();
  return a == Access::Sequential ? seq : rnd;
}

template <class Grid>
void BM_Update(benchmark::State& state, iv::Observation obs, Access access) {
  Grid grid(kRes, kRegion);
  const auto& ks = keys(access);
  // Warm-up pass: allocate every block so the measurement is the steady-state update.
  for (const auto& k : ks) grid.update(k, iv::Observation::Miss);
  std::size_t i = 0;
  for (auto _ : state) {
    for (int n = 0; n < 4096; ++n) {
      grid.update(ks[i], obs);
      if (++i == ks.size()) i = 0;
    }
  }
  benchmark::DoNotOptimize(grid.cell(ks[0]));
  const auto updates = static_cast<double>(state.iterations()) * 4096;
  state.SetItemsProcessed(static_cast<std::int64_t>(updates));
  state.counters["ns_per_update"] =
      benchmark::Counter(updates, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["bytes_per_voxel"] =
      static_cast<double>(grid.memory_bytes()) / static_cast<double>(grid.observed_count());
}

template <class Grid>
void register_grid(const char* name) {
  for (auto access : {Access::Sequential, Access::Random}) {
    for (auto obs : {iv::Observation::Hit, iv::Observation::Miss}) {
      const std::string label = std::string(name) + "/" + (obs == iv::Observation::Hit ? "hit" : "miss") + "/" +
                                (access == Access::Sequential ? "sequential" : "random");
      benchmark::RegisterBenchmark(label.c_str(),
                                   [obs, access](benchmark::State& s) { BM_Update<Grid>(s, obs, access); });
    }
  }
}

template <class U, class S>
using G = iv::VoxelGrid<U, iv::Entropy, S>;

}  // namespace

int main(int argc, char** argv) {
  register_grid<G<iv::BayesLogOdds, iv::DenseStorage>>("bayes/dense");
  register_grid<G<iv::BayesLogOdds, iv::SparseStorage>>("bayes/sparse");
  register_grid<G<iv::IntervalUpdate<iv::LowerState>, iv::DenseStorage>>("interval-lower/dense");
  register_grid<G<iv::IntervalUpdate<iv::MeanState>, iv::DenseStorage>>("interval-mean/dense");
  register_grid<G<iv::IntervalUpdate<iv::MeanState>, iv::SparseStorage>>("interval-mean/sparse");
  register_grid<G<iv::IntervalUpdate<iv::UpperState>, iv::SparseStorage>>("interval-upper/sparse");
  register_grid<G<iv::CompactIntervalUpdate<iv::MeanState>, iv::SparseStorage>>("compact-interval-mean/sparse");
  register_grid<G<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::DenseStorage>>("dirichlet-mean/dense");
  register_grid<G<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::SparseStorage>>("dirichlet-mean/sparse");
  register_grid<G<iv::DempsterShaferUpdate<iv::MeanState>, iv::DenseStorage>>("belief-mean/dense");
  register_grid<G<iv::DempsterShaferUpdate<iv::MeanState>, iv::SparseStorage>>("belief-mean/sparse");
  return bench::run_main(argc, argv);
}
