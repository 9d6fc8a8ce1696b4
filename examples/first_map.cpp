// A first map, end to end: a depth camera in the simulated lab room looks around, every frame is
// inserted into an interval grid, the map is queried, saved, exported and drawn.
// Used by docs/quickstart.md.
#include <intervox/intervox.hpp>
#include <intervox/io/png.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string_view>

#include "common/guarded_main.hpp"

namespace iv = intervox;

int first_map(const std::string& out) {
  std::filesystem::create_directories(out);

  // The world: the thesis' lab room, with a specular (mirror-like) closet against the west wall.
  iv::sim::LabRoomOptions room;
  room.closet_material = iv::sim::Material::specular();
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room);

  // The map: interval update with the mean as state, max-entropy utility, 5 cm voxels, sparse.
  iv::IntervalGrid grid(0.05);

  // The sensor: a 160 x 120 depth camera, 60 x 45 degrees, 5 m range, at 1 m height.
  const auto camera =
      iv::sim::DepthCamera::make(160, 120, 60 * std::numbers::pi / 180, 45 * std::numbers::pi / 180, 0.1, 5.0);
  // No max range here: each frame brings its camera's (no-return pixels are free up to 5 m).
  iv::ScanInserter inserter(iv::InsertOptions{.threads = 0});
  iv::InsertStats total;
  // Look around in 15 degree steps, three frames per heading: each frame is one scan, and one scan
  // updates a voxel at most once, so a voxel needs several frames to become known (5 misses make an
  // interval-mean voxel free, see docs/concepts.md).
  for (int i = 0; i < 72; ++i) {
    const double yaw = (i / 3) * std::numbers::pi / 12;
    const iv::Point3 eye(4.0, 3.0, 1.0);
    const iv::Pose pose = iv::sim::look_at(eye, eye + iv::Point3(std::cos(yaw), std::sin(yaw), -0.1));
    const iv::sim::CameraMeasurement m = iv::sim::simulate(camera, lab.scene, pose, /*seed=*/i);
    total += inserter.insert_depth_image(grid, m);  // a CameraMeasurement is a DepthFrame
  }
  std::printf("inserted %llu rays, %llu voxel steps, %llu hits, %llu misses, %llu skipped\n",
              static_cast<unsigned long long>(total.rays), static_cast<unsigned long long>(total.voxel_steps),
              static_cast<unsigned long long>(total.hits), static_cast<unsigned long long>(total.misses),
              static_cast<unsigned long long>(total.skipped()));

  // Queries: a voxel on the east wall, one in the middle of the room, one inside the closet's noise.
  for (const iv::Point3& p : {iv::Point3(7.99, 3.0, 1.0), iv::Point3(5.0, 3.0, 1.0), iv::Point3(0.8, 2.0, 1.0)}) {
    const iv::Interval i = grid.interval(p);
    std::printf("(%.2f, %.2f, %.2f): state %.2f, interval [%.2f, %.2f], %s, utility %.2f\n", p.x(), p.y(), p.z(),
                grid.probability(p), i.lower, i.upper, std::string(iv::to_string(grid.occupancy(p))).c_str(),
                grid.utility(p));
  }
  const iv::OccupancyCounts c = grid.counts();
  std::printf("%zu observed voxels: %zu free, %zu occupied, %zu unknown; %.1f MB\n", c.observed(), c.free, c.occupied,
              c.unknown, grid.memory_bytes() / 1e6);

  // Keep it, share it, look at it.
  iv::save_grid(out + "/map.ivx", grid);       // own format, reload with load_grid
  iv::write_bt(out + "/map.bt", grid);         // OctoMap viewers (octovis)
  iv::write_ply(out + "/occupied.ply", grid);  // MeshLab, CloudCompare
  iv::SliceOptions slice;
  slice.z = grid.key(iv::Point3(0, 0, 1.0)).z;  // the layer at 1 m height
  slice.pixels_per_voxel = 4;
  slice.color = iv::ColorBy::Table52;  // the thesis' width x state code
  iv::write_png(out + "/slice_table52.png", iv::render_slice(grid, slice));
  std::printf("wrote %s/map.ivx, map.bt, occupied.ply, slice_table52.png\n", out.c_str());
  return 0;
}

// first_map [output folder]: any failure (a folder that cannot be created, a file that cannot be
// written) ends as "first_map: error: ..." and exit code 1; a wrong command line as exit code 2.
int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  const std::string_view arg = argc > 1 ? argv[1] : "";
  if (arg == "-h" || arg == "--help") {
    std::printf("usage: first_map [output folder, default out/first_map]\n");
    return 0;
  }
  if (argc > 2 || arg.starts_with('-')) {
    examples::report_error("first_map", "expected at most one argument, the output folder (usage: first_map [folder])");
    return examples::kUsageError;
  }
  return examples::guarded_main("first_map", [&] { return first_map(argc > 1 ? argv[1] : "out/first_map"); });
}
