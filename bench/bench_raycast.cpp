// Ray insertion on the room frame: a 640x480 depth camera sweeping a furnished 6 x 5 x 3 m room,
// 2 cm voxels, 5 m max range. Intervox (Bayes and interval, sparse and dense, 1 and 2 threads)
// against OctoMap's insertPointCloud in the same binary and run, and the projective insertion
// (raycast/projective.hpp) beside the exact one, with their class agreement printed first.
//
// Run: ./build/bench/bench_raycast --benchmark_counters_tabular=true
#include <intervox/intervox.hpp>
#include <intervox/raycast/projective.hpp>
#include <intervox/raycast/raycast.hpp>
#include "bench_main.hpp"

#include "room_frame.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <utility>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
#include <octomap/octomap.h>
#endif

namespace iv = intervox;

namespace {

using room_frame::camera;
using room_frame::Frame;
using room_frame::frames;
using room_frame::kFrames;
using room_frame::kMaxRange;
using room_frame::kResolution;

const iv::Bounds kRoomBounds{{-0.1, -0.1, -0.1}, {6.1, 5.1, 3.1}};

template <class Grid>
Grid make_grid() {
  if constexpr (Grid::StorageType::kBounded) {
    return Grid(kResolution, kRoomBounds);
  } else {
    return Grid(kResolution);
  }
}

void set_counters(benchmark::State& state, double seconds, std::uint64_t steps, std::size_t bytes, std::size_t voxels) {
  const double frames_done = double(state.iterations()) * double(frames().size());
  state.counters["frame_ms"] = seconds / frames_done * 1e3;
  state.counters["Msteps/s"] = double(steps) / seconds * 1e-6;
  state.counters["ns/step"] = seconds / double(steps) * 1e9;
  state.counters["B/voxel"] = voxels ? double(bytes) / double(voxels) : 0.0;
  state.counters["voxels"] = double(voxels);
}

/// What a row inserts: depth images (exact), point clouds (exact), or depth images by projection
/// (ProjectiveInserter; "Msteps/s" then counts the voxels projected into the image).
enum class Input { Depth, Cloud, Projective };

using Walk = iv::detail::WalkKind;

template <class Grid>
void BM_Intervox(benchmark::State& state, Input input, unsigned threads, Walk walk) {
  const auto& fr = frames();
  const auto k = camera();
  iv::ScanInserter ins({.max_range = kMaxRange, .min_range = 0.0, .threads = threads});
  iv::ProjectiveInserter proj({.max_range = kMaxRange, .min_range = 0.0, .threads = threads});
  iv::detail::ScanInserterAccess::set_walk(ins, walk);
  iv::detail::ScanInserterAccess::set_walk(proj, walk);
  double seconds = 0;
  std::uint64_t steps = 0;
  std::size_t bytes = 0, voxels = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto grid = make_grid<Grid>();
    state.ResumeTiming();
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& f : fr) {
      const auto st = input == Input::Depth        ? ins.insert_depth_image(grid, f.image, k, f.pose)
                      : input == Input::Projective ? proj.insert_depth_image(grid, f.image, k, f.pose)
                                                   : ins.insert_point_cloud(grid, f.origin, f.cloud);
      steps += st.voxel_steps;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.PauseTiming();
    bytes = grid.memory_bytes();
    voxels = grid.observed_count();
    state.ResumeTiming();
  }
  set_counters(state, seconds, steps, bytes, voxels);
}

/// Prints how the projective insertion's map of the frames differs from the exact one's (Bayes,
/// the library's defaults): the voxels each observes, and the class (occupied, free, unknown by
/// the thresholds) of those both observe, as a confusion table.
/// `--surface-band=B` sets the projective insertion's surface band for this comparison.
double g_surface_band = iv::kDefaultSurfaceBand;

void compare_projective() {
  const auto& fr = frames();
  const auto k = camera();
  iv::BayesGrid exact(kResolution), proj(kResolution);
  iv::ScanInserter ex({.max_range = kMaxRange});
  iv::ProjectiveInserter pj({.max_range = kMaxRange}, g_surface_band);
  for (const auto& f : fr) {
    ex.insert_depth_image(exact, f.image, k, f.pose);
    pj.insert_depth_image(proj, f.image, k, f.pose);
  }
  const auto cls = [](iv::Occupancy o) { return o == iv::Occupancy::Occupied ? 0 : o == iv::Occupancy::Free ? 1 : 2; };
  std::size_t both = 0, exact_only = 0, proj_only = 0, table[3][3] = {};  // [exact][projective]
  exact.for_each_observed([&](const iv::Key& key, float) {
    if (!proj.is_observed(key)) {
      ++exact_only;
      return;
    }
    ++both;
    ++table[cls(exact.occupancy(key))][cls(proj.occupancy(key))];
  });
  proj.for_each_observed([&](const iv::Key& key, float) { proj_only += !exact.is_observed(key); });
  const auto pct = [&](std::size_t n) { return 100.0 * double(n) / double(std::max<std::size_t>(both, 1)); };
  std::printf("projective (surface band %.2f) vs exact insertion (%zu frames, Bayes, 2 cm, 5 m): %zu voxels both "
              "observe, the same class "
              "(occupied, free, unknown) %.2f %%; observed only by the exact %zu (%.2f %% of its %zu), only by the "
              "projective %zu (%.2f %% of its %zu)\n",
              g_surface_band, fr.size(), both, pct(table[0][0] + table[1][1] + table[2][2]), exact_only,
              100.0 * double(exact_only) / double(exact.observed_count()), exact.observed_count(), proj_only,
              100.0 * double(proj_only) / double(proj.observed_count()), proj.observed_count());
  const char* names[3] = {"occupied", "free", "unknown"};
  std::printf("  exact \\ projective   occupied       free    unknown\n");
  for (int i = 0; i < 3; ++i)
    std::printf("  %-18s %9zu %10zu %10zu\n", names[i], table[i][0], table[i][1], table[i][2]);
}

/// The same depth frames with every beam classed and its evidence kept apart (ExplainedSpace):
/// the cost of explained free space beside the plain row "intervox/bayes/sparse/depth/1t", at the
/// channel's defaults (the revision ledger revising every 8 frames), without the ledger, and
/// revising after every frame, and with the inside rule for returned beams (at the defaults and
/// without the ledger); each iteration ends with a revision (ExplainedSpace::revise()).
/// With \p known, the channel is first told of those surfaces (a floor plan: every beam is tested
/// against each, ExplainedPlanningParams::known_surfaces).
void BM_Explained(benchmark::State& state, unsigned threads, const iv::ExplainOptions& options,
                  const std::vector<iv::PlanePatch>& known = {}) {
  const auto& fr = frames();
  const auto k = camera();
  iv::ScanInserter ins({.max_range = kMaxRange, .min_range = 0.0, .threads = threads});
  double seconds = 0;
  std::uint64_t steps = 0, suspect = 0, beams = 0;
  std::size_t bytes = 0, voxels = 0, ledger = 0;
  std::uint64_t moved = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto grid = iv::BayesGrid(kResolution);
    iv::ExplainedSpace space(grid.geometry(), options);
    for (const iv::PlanePatch& p : known) space.add_mirror(p, iv::MirrorMerge::Keep);
    state.ResumeTiming();
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& f : fr) {
      iv::DepthFrame frame;
      frame.image = f.image;
      frame.intrinsics = k;
      frame.pose = f.pose;
      const auto st = space.insert_depth_image(ins, grid, frame);
      steps += st.voxel_steps;
      suspect += st.beams_suspect;
      beams += st.rays;
    }
    space.revise();
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.PauseTiming();
    bytes = grid.memory_bytes() + space.memory_bytes();
    voxels = grid.observed_count();
    ledger = space.ledger().bytes();
    moved = space.revision_stats().to_suspect + space.revision_stats().to_trusted;
    state.ResumeTiming();
  }
  set_counters(state, seconds, steps, bytes, voxels);
  state.counters["suspect_%"] = beams ? 100.0 * double(suspect) / double(beams) : 0.0;
  state.counters["ledger_MiB"] = double(ledger) / (1024.0 * 1024.0);
  state.counters["moved"] = double(moved);
}

/// Where the time goes: the bare traversal (visitor counts voxels), then traversal + per-scan
/// marking (de-duplication without the grid update).
void BM_TraversalOnly(benchmark::State& state) {
  const auto& fr = frames();
  const iv::GridGeometry g(kResolution);
  double seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& f : fr) {
      for (const auto& p : f.cloud) {
        const iv::Point3 q = p.cast<double>();
        const double len = (q - f.origin).norm();
        const iv::Point3 end = len > kMaxRange ? iv::Point3(f.origin + (q - f.origin) * (kMaxRange / len)) : q;
        std::uint64_t n = 0;
        iv::traverse(g, f.origin, end, [&](const iv::Key& key) {
          n += static_cast<std::uint64_t>(key.x & 1);
          return true;
        });
        benchmark::DoNotOptimize(n);
      }
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  state.counters["frame_ms"] = seconds / (double(state.iterations()) * double(frames().size())) * 1e3;
}

void BM_TraversalAndMarks(benchmark::State& state) {
  const auto& fr = frames();
  const iv::GridGeometry g(kResolution);
  iv::detail::ScanMarks marks;
  double seconds = 0;
  const iv::InsertOptions opt{.max_range = kMaxRange};
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& f : fr) {
      iv::detail::RayMarker marker(marks, iv::detail::BlockRegion::everywhere(), ~std::size_t{0});
      iv::InsertStats st;
      for (const auto& p : f.cloud)
        if (const auto r = iv::detail::prepare_ray(g, opt, {f.origin, p.cast<double>(), true}, st)) marker.mark(*r);
      benchmark::DoNotOptimize(marks.size());
      marks.clear();
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  state.counters["frame_ms"] = seconds / (double(state.iterations()) * double(frames().size())) * 1e3;
}

#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
std::size_t octomap_voxels(const octomap::OcTree& tree) {
  std::size_t n = 0;
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
    n += std::size_t{1} << (3 * (depth - it.getDepth()));
  return n;
}

octomap::Pointcloud to_octomap(const std::vector<Eigen::Vector3f>& cloud) {
  octomap::Pointcloud pc;
  pc.reserve(cloud.size());
  for (const auto& p : cloud) pc.push_back(p.x(), p.y(), p.z());
  return pc;
}

void BM_OctoMap(benchmark::State& state) {
  const auto& fr = frames();
  std::vector<octomap::Pointcloud> clouds;
  for (const auto& f : fr) clouds.push_back(to_octomap(f.cloud));
  double seconds = 0;
  std::uint64_t steps = 0;
  std::size_t bytes = 0, voxels = 0;
  // The same voxel steps as Intervox's traversal (identical rays).
  iv::BayesGrid probe(kResolution);
  iv::ScanInserter ins({.max_range = kMaxRange});
  std::uint64_t steps_per_run = 0;
  for (const auto& f : fr) steps_per_run += ins.insert_point_cloud(probe, f.origin, f.cloud).voxel_steps;
  for (auto _ : state) {
    octomap::OcTree tree(kResolution);
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < fr.size(); ++i) {
      const octomap::point3d o(float(fr[i].origin.x()), float(fr[i].origin.y()), float(fr[i].origin.z()));
      tree.insertPointCloud(clouds[i], o, kMaxRange);  // lazy_eval = false, discretize = false (defaults)
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    steps += steps_per_run;
    bytes = tree.memoryUsage();
    voxels = octomap_voxels(tree);
  }
  set_counters(state, seconds, steps, bytes, voxels);
}

/// Box queries (OctoMap's leaf_bbx iterator against VoxelGrid::for_each_observed_in) on the map of
/// the first frame, inserted as the same point cloud into both: 200 seeded boxes of 0.2 to 1 m in
/// the room, each visiting every observed voxel (OctoMap: leaf) that meets it; "voxels" counts
/// the voxels visited per query (a pruned OctoMap leaf of free space counts once; the expanded
/// tree has one leaf per voxel, as Intervox's grid).
struct QueryMaps {
  iv::BayesGrid grid{kResolution, iv::BayesLogOdds::octomap()};
  octomap::OcTree tree{kResolution};
  std::unique_ptr<octomap::OcTree> expanded;  // the same tree with every leaf at full depth (one per voxel)
  std::vector<iv::Bounds> boxes;
  QueryMaps() {
    const auto& f = frames()[0];
    iv::insert_point_cloud(grid, f.origin, f.cloud, {.max_range = kMaxRange});
    tree.insertPointCloud(to_octomap(f.cloud),
                          octomap::point3d(float(f.origin.x()), float(f.origin.y()), float(f.origin.z())), kMaxRange);
    expanded = std::make_unique<octomap::OcTree>(tree);
    expanded->expand();
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> at(0.0, 1.0), size(0.2, 1.0);
    for (int i = 0; i < 200; ++i) {
      const iv::Point3 lo(at(rng) * 5.0, at(rng) * 4.0, at(rng) * 2.0);
      boxes.push_back({lo, lo + iv::Point3(size(rng), size(rng), size(rng))});
    }
  }
};
const QueryMaps& query_maps() {
  static const QueryMaps m;
  return m;
}

/// \p octomap: 0 Intervox, 1 OctoMap's pruned tree, 2 OctoMap's tree expanded to one leaf per voxel.
void BM_BoxQuery(benchmark::State& state, int octomap) {
  const QueryMaps& m = query_maps();
  std::uint64_t visited = 0, queries = 0;
  double sum = 0, seconds = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& b : m.boxes) {
      if (octomap) {
        const octomap::OcTree& tree = octomap == 1 ? m.tree : *m.expanded;
        const octomap::point3d lo(float(b.min.x()), float(b.min.y()), float(b.min.z())),
            hi(float(b.max.x()), float(b.max.y()), float(b.max.z()));
        for (auto it = tree.begin_leafs_bbx(lo, hi), end = tree.end_leafs_bbx(); it != end; ++it) {
          sum += it->getLogOdds();
          ++visited;
        }
      } else {
        m.grid.for_each_observed_in(b, [&](const iv::Key&, float c) {
          sum += c;
          ++visited;
        });
      }
      ++queries;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  benchmark::DoNotOptimize(sum);
  const double q = double(std::max<std::uint64_t>(queries, 1));
  state.counters["us/query"] = seconds / q * 1e6;
  state.counters["voxels"] = double(visited) / q;  // voxels (OctoMap: leaves) visited per query
  state.counters["ns/voxel"] = seconds / double(std::max<std::uint64_t>(visited, 1)) * 1e9;
}

/// Coarse queries (OctoMap's inner nodes, `search(key, 16 - level)`, against CoarseSummary) on the
/// map of QueryMaps: 2,000 seeded keys in the room, each asking the largest probability and whether
/// anything is occupied in the cube of 2^level voxels that holds it. \p mode: 0 CoarseSummary, 1
/// OctoMap's tree, 2 Intervox without summaries (for_each_observed_in over the cube's voxels).
/// "build_ms" is CoarseSummary's construction (OctoMap updates its inner nodes during insertion).
void BM_CoarseQuery(benchmark::State& state, int mode) {
  const QueryMaps& m = query_maps();
  const int level = static_cast<int>(state.range(0));
  std::vector<iv::Key> keys;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> at(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) keys.push_back(m.grid.key(iv::Point3(at(rng) * 5.0, at(rng) * 4.0, at(rng) * 2.0)));
  const auto b0 = std::chrono::steady_clock::now();
  const iv::CoarseSummary<iv::BayesGrid> cs(m.grid);
  const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - b0).count();
  double sum = 0, seconds = 0;
  std::uint64_t queries = 0, occupied = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const iv::Key& k : keys) {
      if (mode == 1) {
        const auto* node = m.tree.search(octomap::OcTreeKey(k.x + 32768, k.y + 32768, k.z + 32768), 16 - level);
        if (node) {
          sum += node->getLogOdds();
          occupied += m.tree.isNodeOccupied(node);
        }
      } else if (mode == 0) {
        const iv::CubeSummary s = cs.summary(k, level);
        sum += s.max_probability;
        occupied += s.any_occupied();
      } else {
        float best = -1e9f;
        bool occ = false;
        m.grid.for_each_observed_in(iv::CoarseSummary<iv::BayesGrid>::cube(k, level), [&](const iv::Key&, float c) {
          best = std::max(best, c);
          occ = occ || m.grid.update_policy().occupancy(c) == iv::Occupancy::Occupied;
        });
        sum += best;
        occupied += occ;
      }
      ++queries;
    }
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  benchmark::DoNotOptimize(sum);
  const double q = double(std::max<std::uint64_t>(queries, 1));
  state.counters["ns/query"] = seconds / q * 1e9;
  state.counters["occupied"] = double(occupied) / q;  // share of cubes with an occupied voxel (equal across rows)
  if (mode == 0) {
    state.counters["build_ms"] = build * 1e3;
    state.counters["map_voxels"] = double(m.grid.observed_count());
    state.counters["cubes"] = double(cs.cube_count(level));
  }
}

/// Change detection's cost: the first two frames inserted as point clouds (Bayes with OctoMap's
/// parameters), with and without change detection; with it, the changed keys are read and the
/// record reset after each frame, as a costmap would. "changed" counts the keys per frame.
void BM_Changes(benchmark::State& state, bool octomap, bool detect) {
  const auto& fr = frames();
  const std::size_t n = std::min<std::size_t>(2, fr.size());
  std::vector<octomap::Pointcloud> clouds;
  for (std::size_t i = 0; i < n; ++i) clouds.push_back(to_octomap(fr[i].cloud));
  double seconds = 0;
  std::uint64_t changed = 0, inserted = 0;
  for (auto _ : state) {
    if (octomap) {
      octomap::OcTree tree(kResolution);
      tree.enableChangeDetection(detect);
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < n; ++i) {
        const octomap::point3d o(float(fr[i].origin.x()), float(fr[i].origin.y()), float(fr[i].origin.z()));
        tree.insertPointCloud(clouds[i], o, kMaxRange);
        if (detect) {
          for (auto it = tree.changedKeysBegin(); it != tree.changedKeysEnd(); ++it) ++changed;
          tree.resetChangeDetection();
        }
      }
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    } else {
      iv::BayesGrid grid(kResolution, iv::BayesLogOdds::octomap());
      grid.enable_change_detection(detect);
      iv::ScanInserter ins({.max_range = kMaxRange});
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < n; ++i) {
        ins.insert_point_cloud(grid, fr[i].origin, fr[i].cloud);
        if (detect) {
          changed += grid.changed_keys().size();
          grid.reset_change_detection();
        }
      }
      seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    inserted += n;
  }
  state.counters["frame_ms"] = seconds / double(std::max<std::uint64_t>(inserted, 1)) * 1e3;
  state.counters["changed"] = double(changed) / double(std::max<std::uint64_t>(inserted, 1));
}

/// Prints how many voxels differ between OctoMap and Intervox's Bayes grid (OctoMap preset).
void compare_with_octomap() {
  const auto& fr = frames();
  octomap::OcTree tree(kResolution);
  iv::BayesGrid grid(kResolution, iv::BayesLogOdds::octomap());
  iv::ScanInserter ins({.max_range = kMaxRange});
  for (const auto& f : fr) {
    const octomap::point3d o(float(f.origin.x()), float(f.origin.y()), float(f.origin.z()));
    tree.insertPointCloud(to_octomap(f.cloud), o, kMaxRange);
    ins.insert_point_cloud(grid, f.origin, f.cloud);
  }
  tree.expand();
  std::size_t octo = 0, equal = 0, differ = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    ++octo;
    const auto k = it.getKey();
    const iv::Key key{int(k[0]) - 32768, int(k[1]) - 32768, int(k[2]) - 32768};
    const float ours = grid.cell(key);
    const bool same = grid.is_observed(key) &&
                      std::abs(grid.update_policy().log_odds(ours) - it->getLogOdds()) <= 1e-5f &&
                      ((grid.occupancy(key) == iv::Occupancy::Occupied) == tree.isNodeOccupied(*it));
    (same ? equal : differ) += 1;
  }
  std::size_t ours_only = 0;
  grid.for_each_observed([&](const iv::Key& k, float) {
    const octomap::OcTreeKey ok(k.x + 32768, k.y + 32768, k.z + 32768);
    if (!tree.search(ok)) ++ours_only;
  });
  std::printf("OctoMap check (10 frames as point clouds): OctoMap %zu voxels, Intervox %zu; %zu identical, "
              "%zu differ (value, class or presence: %.1e of all; float-vs-double ties on voxel edges)\n",
              octo, grid.observed_count(), equal, differ + ours_only,
              double(differ + ours_only) / double(std::max<std::size_t>(octo, 1)));
}
#endif

}  // namespace

BENCHMARK(BM_TraversalOnly)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();
BENCHMARK(BM_TraversalAndMarks)->Unit(benchmark::kMillisecond)->Iterations(2)->UseRealTime();
#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
BENCHMARK(BM_OctoMap)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_BoxQuery, octomap_leaf_bbx, 1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BoxQuery, octomap_leaf_bbx_expanded, 2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_BoxQuery, intervox_for_each_observed_in, 0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_CoarseQuery, octomap_search, 1)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_CoarseQuery, intervox_summary, 0)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_CoarseQuery, intervox_box_scan, 2)->Arg(3)->Arg(5)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Changes, octomap_off, true, false)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();
BENCHMARK_CAPTURE(BM_Changes, octomap_change_detection, true, true)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Changes, intervox_off, false, false)->Unit(benchmark::kMillisecond)->Iterations(3)->UseRealTime();
BENCHMARK_CAPTURE(BM_Changes, intervox_change_detection, false, true)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
#endif

/// Iterations of every registered row: 3, or 1 in a smoke run (which also builds one frame).
int g_iterations = 3;

template <class Grid>
void add(const char* name, Input input, unsigned threads, Walk walk = Walk::Fastest) {
  benchmark::RegisterBenchmark(name, [=](benchmark::State& st) { BM_Intervox<Grid>(st, input, threads, walk); })
      ->Unit(benchmark::kMillisecond)
      ->Iterations(g_iterations)
      ->UseRealTime();
}

/// Profiling mode, for callgrind or CPU-time runs without Google Benchmark's repetitions:
/// `bench_raycast --profile=<what> [--frames=N]` inserts the first N frames (default 10) once and
/// prints the process CPU time. what: bayes, bayes2t, bayes-avx2, bayes-table, bayes-single (the
/// slower walks), interval, interval2t, compact, dense, projective, projective2t, marks, traverse, octomap.
/// The walk a --profile variant forces (Fastest unless its name ends in -avx2, -table or -single).
Walk walk_of(const std::string& what) {
  if (what.ends_with("-avx2")) return Walk::Avx2;
  if (what.ends_with("-table")) return Walk::Table;
  if (what.ends_with("-single")) return Walk::Single;
  return Walk::Fastest;
}

int profile(const std::string& what, int n) {
  const auto& fr = frames();  // built before the clock starts
  const auto k = camera();
  const std::clock_t c0 = std::clock();
  const auto w0 = std::chrono::steady_clock::now();
  std::uint64_t steps = 0;
  auto depth = [&](auto grid, unsigned threads, Walk walk = Walk::Fastest) {
    iv::ScanInserter ins({.max_range = kMaxRange, .min_range = 0.0, .threads = threads});
    iv::detail::ScanInserterAccess::set_walk(ins, walk);
    for (int i = 0; i < n; ++i) steps += ins.insert_depth_image(grid, fr[i].image, k, fr[i].pose).voxel_steps;
    benchmark::DoNotOptimize(grid.observed_count());
  };
  if (what == "bayes")
    depth(iv::BayesGrid(kResolution), 1);
  else if (what == "bayes2t")
    depth(iv::BayesGrid(kResolution), 2);
  else if (what == "bayes-avx2")
    depth(iv::BayesGrid(kResolution), 1, Walk::Avx2);
  else if (what == "bayes-table")
    depth(iv::BayesGrid(kResolution), 1, Walk::Table);
  else if (what == "bayes-single")
    depth(iv::BayesGrid(kResolution), 1, Walk::Single);
  else if (what == "interval")
    depth(iv::IntervalGrid(kResolution), 1);
  else if (what == "interval2t")
    depth(iv::IntervalGrid(kResolution), 2);
  else if (what == "compact")
    depth(iv::CompactIntervalGrid(kResolution), 1);
  else if (what == "dense")
    depth(iv::DenseBayesGrid(kResolution, kRoomBounds), 1);
  else if (what == "projective" || what == "projective2t") {
    iv::BayesGrid grid(kResolution);
    iv::ProjectiveInserter ins({.max_range = kMaxRange, .threads = what == "projective" ? 1u : 2u});
    for (int i = 0; i < n; ++i) steps += ins.insert_depth_image(grid, fr[i].image, k, fr[i].pose).voxel_steps;
    benchmark::DoNotOptimize(grid.observed_count());
  } else if (what == "marks" || what == "traverse") {
    const iv::GridGeometry g(kResolution);
    iv::detail::ScanMarks marks;
    const iv::InsertOptions opt{.max_range = kMaxRange};
    for (int i = 0; i < n; ++i) {
      iv::detail::RayMarker marker(marks, iv::detail::BlockRegion::everywhere(), ~std::size_t{0});
      iv::InsertStats st;
      for (const auto& p : fr[i].cloud) {
        const auto r = iv::detail::prepare_ray(g, opt, {fr[i].origin, p.cast<double>(), true}, st);
        if (!r) continue;
        const iv::Point3 &v0 = r->v0, &v1 = r->v1;
        const iv::Key &k0 = r->k0, &k1 = r->k1;
        const bool hit = r->hit;
        if (what == "marks") {
          marker.mark(*r);
          steps += static_cast<std::uint64_t>(std::abs(k1.x - k0.x) + std::abs(k1.y - k0.y) + std::abs(k1.z - k0.z)) +
                   (hit ? 1 : 0);
        } else {
          std::uint64_t c = 0;
          iv::traverse(g, iv::Point3(v0 * kResolution), iv::Point3(v1 * kResolution), [&](const iv::Key& key) {
            c += static_cast<std::uint64_t>(key.x & 1);
            return true;
          });
          benchmark::DoNotOptimize(c);
        }
      }
      marks.clear();
    }
  }
#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
  else if (what == "octomap") {
    octomap::OcTree tree(kResolution);
    for (int i = 0; i < n; ++i) {
      const octomap::point3d o(float(fr[i].origin.x()), float(fr[i].origin.y()), float(fr[i].origin.z()));
      tree.insertPointCloud(to_octomap(fr[i].cloud), o, kMaxRange);
    }
  }
#endif
  else {
    std::fprintf(stderr, "unknown --profile=%s\n", what.c_str());
    return 1;
  }
  const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;  // all threads
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  std::printf(
      "profile %s (%s walk): %d frames, %.1f ms CPU per frame (all threads), %.1f ms real, %.1f M steps per frame\n",
      what.c_str(), what == "octomap" ? "no" : iv::detail::walk_name(walk_of(what)), n, cpu / n * 1e3, wall / n * 1e3,
      double(steps) / n * 1e-6);
  return 0;
}

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // also for --profile, which runs outside Google Benchmark
  {
    std::string what;
    int n = kFrames;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a.rfind("--profile=", 0) == 0) what = a.substr(10);
      if (a.rfind("--frames=", 0) == 0) n = std::clamp(std::atoi(a.c_str() + 9), 1, kFrames);
      if (a.rfind("--surface-band=", 0) == 0) g_surface_band = std::atof(a.c_str() + 15);
    }
    if (!what.empty()) return profile(what, n);
    int kept = 1;  // --surface-band is ours, not Google Benchmark's
    for (int i = 1; i < argc; ++i)
      if (std::string(argv[i]).rfind("--surface-band=", 0) != 0) argv[kept++] = argv[i];
    argc = kept;
    for (int i = 1; i < argc; ++i)
      if (std::string(argv[i]) == "--smoke") {  // one frame, one iteration per row (bench::run_main drops the flag)
        room_frame::frame_count() = 1;
        g_iterations = 1;
      }
  }
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t", Input::Depth, 1);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t/avx2", Input::Depth, 1, Walk::Avx2);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t/portable-table", Input::Depth, 1, Walk::Table);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t/portable-single", Input::Depth, 1, Walk::Single);
  add<iv::BayesGrid>("intervox/bayes/sparse/cloud/1t", Input::Cloud, 1);
  add<iv::DenseBayesGrid>("intervox/bayes/dense/depth/1t", Input::Depth, 1);
  add<iv::IntervalGrid>("intervox/interval/sparse/depth/1t", Input::Depth, 1);
  add<iv::DenseIntervalGrid>("intervox/interval/dense/depth/1t", Input::Depth, 1);
  add<iv::CompactIntervalGrid>("intervox/compact-interval/sparse/depth/1t", Input::Depth, 1);
  add<iv::DirichletGrid>("intervox/dirichlet/sparse/depth/1t", Input::Depth, 1);
  add<iv::BeliefGrid>("intervox/belief/sparse/depth/1t", Input::Depth, 1);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/2t", Input::Depth, 2);
  add<iv::DenseBayesGrid>("intervox/bayes/dense/depth/2t", Input::Depth, 2);
  add<iv::IntervalGrid>("intervox/interval/sparse/depth/2t", Input::Depth, 2);
  add<iv::DenseIntervalGrid>("intervox/interval/dense/depth/2t", Input::Depth, 2);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t/projective", Input::Projective, 1);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/1t/projective-portable", Input::Projective, 1, Walk::Table);
  add<iv::BayesGrid>("intervox/bayes/sparse/depth/2t/projective", Input::Projective, 2);
  add<iv::DenseBayesGrid>("intervox/bayes/dense/depth/1t/projective", Input::Projective, 1);
  add<iv::IntervalGrid>("intervox/interval/sparse/depth/1t/projective", Input::Projective, 1);
  iv::ExplainOptions no_ledger, every_frame;
  no_ledger.ledger_bytes = 0;
  every_frame.revision_interval = 1;
  for (const unsigned t : {1u, 2u})
    for (const auto& [suffix, options] : {std::pair<std::string, iv::ExplainOptions>{"", iv::ExplainOptions{}},
                                          {"/no-ledger", no_ledger},
                                          {"/revise-every-frame", every_frame}})
      benchmark::RegisterBenchmark(
          (std::string("intervox/bayes/sparse/depth/") + (t == 1 ? "1t" : "2t") + "/explained" + suffix).c_str(),
          [t, options](benchmark::State& st) { BM_Explained(st, t, options); })
          ->Unit(benchmark::kMillisecond)
          ->Iterations(g_iterations)
          ->UseRealTime();
  // The inside rule for returned beams (ExplainOptions::returned_crossing_inside), at the defaults
  // and without the ledger.
  iv::ExplainOptions inside, inside_no_ledger = no_ledger;
  inside.returned_crossing_inside = inside_no_ledger.returned_crossing_inside = true;
  for (const auto& [suffix, options] :
       {std::pair<std::string, iv::ExplainOptions>{"/inside", inside}, {"/no-ledger/inside", inside_no_ledger}})
    benchmark::RegisterBenchmark(("intervox/bayes/sparse/depth/1t/explained" + suffix).c_str(),
                                 [options](benchmark::State& st) { BM_Explained(st, 1, options); })
        ->Unit(benchmark::kMillisecond)
        ->Iterations(g_iterations)
        ->UseRealTime();
  // The room's floor plan as a user would tell it: each of the four walls' inner faces in three
  // pieces (as around doors and windows), 12 rectangles.
  std::vector<iv::PlanePatch> floor_plan;
  for (int piece = 0; piece < 3; ++piece) {
    const auto wall = [&](int axis, double at, double lo, double hi) {
      iv::PlanePatch p;
      p.normal = iv::Point3::Unit(axis);
      p.axis_u = iv::PlanePatch::floor_axis(p.normal);
      const double a = lo + (hi - lo) * piece / 3.0, b = lo + (hi - lo) * (piece + 1) / 3.0;
      p.center = axis == 0 ? iv::Point3(at, 0.5 * (a + b), 1.5) : iv::Point3(0.5 * (a + b), at, 1.5);
      p.half_u = 0.5 * (b - a);
      p.half_v = 1.5;
      floor_plan.push_back(p);
    };
    wall(0, 0.0, 0.0, 5.0);
    wall(0, 6.0, 0.0, 5.0);
    wall(1, 0.0, 0.0, 6.0);
    wall(1, 5.0, 0.0, 6.0);
  }
  benchmark::RegisterBenchmark(
      "intervox/bayes/sparse/depth/1t/explained/no-ledger/floor-plan",
      [no_ledger, floor_plan](benchmark::State& st) { BM_Explained(st, 1, no_ledger, floor_plan); })
      ->Unit(benchmark::kMillisecond)
      ->Iterations(g_iterations)
      ->UseRealTime();
  return bench::run_main(argc, argv, [] {
    std::printf("marking walk on this processor: %s\n", iv::insertion_walk());
    compare_projective();
#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
    compare_with_octomap();
#else
    std::printf("OctoMap not found (Debian liboctomap-dev): the OctoMap comparison is skipped\n");
#endif
  });
}
