// What long rays cost: time, and the inserter's scratch memory, for scans with stray returns far
// away (issue: one point 100 km away at 2 cm used to keep 336 MB of scratch). Default options
// everywhere (no max range), as a new user inserts; the grid is bounded, so that the counters
// show the inserter's memory and not the map's.
//
// Run: ./build/bench/bench_long_rays --benchmark_counters_tabular=true
// The file uses only API that existed before the mark budget, so the same scenarios can be built
// against an older checkout for a side-by-side comparison (see docs/performance.md).
#include <benchmark/benchmark.h>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>
#include "bench_main.hpp"

#include <random>
#include <vector>

namespace iv = intervox;

namespace {

const iv::Bounds kRoom{{-5, -5, -5}, {5, 5, 5}};

/// A room-like scan: \p n points within 4 m, plus \p stray points \p far metres away.
std::vector<iv::Point3> scan(int n, int stray, double far, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.5, 4.0);
  std::vector<iv::Point3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(iv::Point3(gauss(rng), gauss(rng), 0.3 * gauss(rng)).normalized() * r(rng));
  for (int i = 0; i < stray; ++i) pts.push_back(iv::Point3(gauss(rng), gauss(rng), gauss(rng)).normalized() * far);
  return pts;
}

void BM_Scan(benchmark::State& state, int n, int stray, double far, unsigned threads) {
  const auto pts = scan(n, stray, far, 1);
  iv::ScanInserter inserter({.threads = threads});
  std::uint64_t steps = 0;
  std::size_t scratch = 0;
  for (auto _ : state) {
    iv::IntervalGrid grid(0.02, kRoom);
    const auto st = inserter.insert_point_cloud(grid, iv::Point3(0.01, 0.02, 0.03), pts);
    steps += st.voxel_steps;
    scratch = std::max(scratch, inserter.scratch_bytes());
    benchmark::DoNotOptimize(grid.observed_count());
  }
  state.counters["Msteps"] = double(steps) / double(state.iterations()) * 1e-6;
  state.counters["scratch_MiB"] = double(scratch) / double(1 << 20);
}

}  // namespace

int main(int argc, char** argv) {
  // Iterations of every row: as below, or one in a smoke run.
  const bool smoke = bench::has_smoke_flag(argc, argv);
  auto row = [&](const char* name, int n, int stray, double far, unsigned threads, int iterations) {
    benchmark::RegisterBenchmark(name, BM_Scan, n, stray, far, threads)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(smoke ? 1 : iterations);
  };
  // A 20 k-point room scan alone, and with one stray return 100 km away (5 M voxels at 2 cm).
  row("BM_Scan/room_20k_1t", 20000, 0, 0.0, 1u, 3);
  row("BM_Scan/room_20k_plus_1_at_100km_1t", 20000, 1, 1e5, 1u, 3);
  row("BM_Scan/room_20k_plus_1_at_100km_2t", 20000, 1, 1e5, 2u, 3);
  // A scan whose points all lie up to 1 km away (a sky full of stray returns): 1000 rays.
  row("BM_Scan/stray_1000_at_1km_1t", 0, 1000, 1e3, 1u, 1);
  row("BM_Scan/stray_1000_at_1km_2t", 0, 1000, 1e3, 2u, 1);
  return bench::run_main(argc, argv);
}
