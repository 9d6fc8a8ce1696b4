// File size and save/load time of the grid file format: .ivx version 1 (uncompressed voxel list)
// and version 2 (8^3 block runs + zstd) against OctoMap's .bt (maximum likelihood, pruned) and .ot
// (full-precision log-odds, pruned) of the same Bayes map, written and read by liboctomap.
//
// Maps: the demo map (the final map of examples/mobile_exploration with --update bayes
// --utility entropy and its other defaults: lab room, diffuse closet, seed 1, 5 cm, 30 steps) and
// the room-frame map of bench_raycast.cpp (the same ten seeded 640x480 depth frames, 2 cm, 5 m max
// range, BayesGrid). Times are the best of five runs, in memory (no disk).
//
// Run: ./build/bench/bench_grid_file [--skip-demo]
#include <intervox/intervox.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>

#include "room_frame.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
#include <octomap/octomap.h>
#endif

namespace iv = intervox;

namespace {

double best_ms(const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 5; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

// ---- the room frame of bench_raycast.cpp (bench/room_frame.hpp) -----------------------------

iv::BayesGrid room_frame_map() {
  iv::BayesGrid grid(room_frame::kResolution);
  iv::ScanInserter ins({.max_range = room_frame::kMaxRange, .min_range = 0.0, .threads = 1});
  for (const auto& f : room_frame::frames()) ins.insert_depth_image(grid, f.image, room_frame::camera(), f.pose);
  return grid;
}

// ---- the demo map: mobile_exploration's final map (bayes / entropy, defaults) ---------------

iv::BayesGrid demo_map() {
  iv::sim::LabRoomOptions room_options;
  room_options.closet_material = iv::sim::Material::of(iv::sim::surface_from_string("diffuse"));
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room_options);
  iv::BayesGrid grid(0.05);
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};  // the lab room's floor, as the example
  p.seed = 1;
  p.threads = 0;
  p.max_steps = 30;
  p.gain_stride = 4;
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  iv::MobilePlanner planner(rig, p);
  iv::Episode episode(grid, planner, iv::sim::SimulatedRig(lab.scene, rig, 1), iv::planar_pose(lab.start, 0.0));
  while (episode.step().plan.termination == iv::Termination::Running) {
  }
  return grid;
}

// ---- the table -------------------------------------------------------------------------------

void row(const char* format, std::size_t bytes, std::size_t voxels, double save_ms, double load_ms) {
  std::printf("| %-34s | %10zu | %6.2f | %8.1f | %8.1f |\n", format, bytes, double(bytes) / double(voxels), save_ms,
              load_ms);
}

void compare(const char* name, const iv::BayesGrid& grid) {
  const std::size_t voxels = grid.observed_count();
  const iv::GridFileInfo info =
      iv::read_grid_file_info_from_memory(iv::save_grid_to_memory(grid, iv::GridSaveOptions{2, 0}));
  std::printf("\n%s: %zu observed voxels (%zu occupied) in %llu blocks, %.3f m; %.1f MiB as a sparse grid\n\n", name,
              voxels, grid.counts().occupied, static_cast<unsigned long long>(info.block_count), grid.resolution(),
              double(grid.memory_bytes()) / (1 << 20));
  std::printf("| %-34s | %10s | %6s | %8s | %8s |\n|---|---:|---:|---:|---:|\n", "format", "bytes", "B/voxel",
              "save ms", "load ms");
  auto ivx = [&](const char* label, iv::GridSaveOptions options) {
    std::string bytes;
    const double save = best_ms([&] { bytes = iv::save_grid_to_memory(grid, options); });
    std::size_t n = 0;
    const double load = best_ms([&] { n = iv::load_grid_from_memory<iv::BayesGrid>(bytes).observed_count(); });
    if (n != voxels) std::printf("MISMATCH: %zu voxels loaded\n", n);
    row(label, bytes.size(), voxels, save, load);
  };
  ivx(".ivx version 1 (before)", iv::GridSaveOptions{1, 0});
  ivx(".ivx version 2, body not compressed", iv::GridSaveOptions{2, 0});
  ivx(".ivx version 2, zstd 3", iv::GridSaveOptions{2, 3});
  ivx(".ivx version 2, zstd 9 (default)", iv::GridSaveOptions{2, 9});
  ivx(".ivx version 2, zstd 19", iv::GridSaveOptions{2, 19});
#ifdef INTERVOX_BENCH_HAVE_OCTOMAP
  // The same map in OctoMap: every observed voxel's log-odds, clamped as the grid clamps.
  const iv::BayesParams& bp = grid.update_policy().params();
  octomap::OcTree tree(grid.resolution());
  tree.setClampingThresMin(bp.clamp_min);
  tree.setClampingThresMax(bp.clamp_max);
  grid.for_each_observed([&](const iv::Key& k, float c) {
    tree.setNodeValue(
        octomap::OcTreeKey(static_cast<octomap::key_type>(k.x + 32768), static_cast<octomap::key_type>(k.y + 32768),
                           static_cast<octomap::key_type>(k.z + 32768)),
        c, true);
  });
  tree.updateInnerOccupancy();
  tree.prune();
  std::string ot;
  const double ot_save = best_ms([&] {
    std::stringstream s;
    tree.write(s);
    ot = s.str();
  });
  const double ot_load = best_ms([&] {
    std::stringstream s(ot);
    delete octomap::AbstractOcTree::read(s);
  });
  row(".ot (OctoMap, full precision)", ot.size(), voxels, ot_save, ot_load);
  std::string bt;
  octomap::OcTree ml(tree);  // writeBinary converts to maximum likelihood in place (idempotent)
  const double bt_save = best_ms([&] {
    std::stringstream s;
    ml.writeBinary(s);
    bt = s.str();
  });
  const double bt_load = best_ms([&] {
    std::stringstream s(bt);
    octomap::OcTree t(0.1);
    t.readBinary(s);
  });
  row(".bt (OctoMap, maximum likelihood)", bt.size(), voxels, bt_save, bt_load);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the maps are built by insertion
  // --skip-demo: the room-frame map only; --smoke (the CTest smoke run): the map of one room frame
  // only. Other options (Google Benchmark's, given to every benchmark program by CTest) are
  // ignored: no Google Benchmark here.
  bool skip_demo = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--skip-demo") skip_demo = true;
    if (std::string(argv[i]) == "--smoke") {
      skip_demo = true;
      room_frame::frame_count() = 1;  // the map of one frame
    }
  }
  std::printf("bench_grid_file: sizes and in-memory save / load times (best of 5)\n");
  if (!skip_demo) compare("demo map (mobile_exploration final map, bayes / entropy)", demo_map());
  compare("room-frame map (bench_raycast, BayesGrid)", room_frame_map());
  return 0;
}
