// Replays a recorded depth sequence in the TUM RGB-D layout (depth/*.png, depth.txt,
// groundtruth.txt) into a map with any update policy, prints per-frame statistics, saves the map
// (own format and OctoMap .bt), writes a top view, and asks the mobile planner for the next best
// view from the last pose. Try it on the committed sequence:
//   replay tests/data/tum_lab --camera sim32
#include <intervox/core/sensors.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/depth_sequence.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/png.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/vector_walks.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>
#include <intervox/view/slice.hpp>

#include "common/cli.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <numbers>
#include <string>

namespace iv = intervox;

namespace {

struct Options {
  std::string folder;
  std::string camera = "tum-fr1";
  std::string update = "interval-mean";
  double depth_factor = 5000.0;
  double resolution = 0.05;
  double max_range = 4.0;
  std::string out = "out/replay";
};

/// Pinhole intrinsics of common depth cameras (docs/io.md).
iv::PinholeIntrinsics intrinsics_of(const std::string& name) {
  iv::PinholeIntrinsics k;
  k.width = 640;
  k.height = 480;
  if (name == "tum-fr1") k.fx = 517.3, k.fy = 516.5, k.cx = 318.6, k.cy = 255.3;
  if (name == "tum-fr2") k.fx = 520.9, k.fy = 521.0, k.cx = 325.1, k.cy = 249.7;
  if (name == "tum-fr3") k.fx = 535.4, k.fy = 539.2, k.cx = 320.1, k.cy = 247.6;
  if (name == "kinect") k.fx = 525.0, k.fy = 525.0, k.cx = 319.5, k.cy = 239.5;
  if (name == "o3d100") k = iv::DepthCamera::o3d100().intrinsics;
  if (name == "sim32") k = iv::PinholeIntrinsics::from_fov(32, 24, iv::deg(60), iv::deg(45));  // tests/data/tum_lab
  return k;
}

template <class Grid>
int run(const Options& o) {
  iv::DepthSequenceOptions so;
  so.depth_factor = o.depth_factor;
  const iv::DepthSequence seq = iv::DepthSequence::open(o.folder, intrinsics_of(o.camera), so);
  if (seq.size() == 0) throw iv::IoError("replay: no depth frame of '" + o.folder + "' has a ground-truth pose");
  Grid grid(o.resolution);
  iv::InsertOptions io;
  io.max_range = o.max_range;
  std::printf("replay %s: %zu of %zu depth frames with a pose, %s, %.3f m voxels\n", o.folder.c_str(), seq.size(),
              seq.depth_frames(), std::string(Grid::UpdateType::kName).c_str(), o.resolution);
  std::printf("%6s %12s %8s %9s %9s %10s %10s %10s %8s\n", "frame", "time", "rays", "hits", "misses", "free",
              "occupied", "unknown", "s");
  for (std::size_t i = 0; i < seq.size(); ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const iv::InsertStats st = iv::insert_depth_image(grid, seq.frame(i), io);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto c = grid.counts();
    std::printf("%6zu %12.3f %8llu %9llu %9llu %10zu %10zu %10zu %8.3f  [%3.0f %%]\n", i, seq.frames()[i].time,
                static_cast<unsigned long long>(st.rays), static_cast<unsigned long long>(st.hits),
                static_cast<unsigned long long>(st.misses), c.free, c.occupied, c.unknown, s,
                100.0 * double(i + 1) / double(seq.size()));
  }
  std::filesystem::create_directories(o.out);
  iv::save_grid(o.out + "/map.ivx", grid);
  iv::write_bt(o.out + "/map.bt", grid);
  iv::SliceOptions slice;
  slice.mode = iv::SliceMode::MaxProjection;
  slice.pixels_per_voxel = 4;
  iv::write_png(o.out + "/top.png", iv::render_slice(grid, slice));
  std::printf("saved %s/map.ivx, %s/map.bt, %s/top.png\n", o.out.c_str(), o.out.c_str(), o.out.c_str());

  // The next best view for a mobile base carrying this camera, from the last pose: the body stands
  // on the floor (z = 0 of the recording's world frame) under the camera, facing where it looks.
  const iv::Pose camera = seq.frames().back().pose;
  const iv::Point3 look = camera.linear().col(2);
  const iv::Pose body = iv::planar_pose(iv::Point3(camera.translation().x(), camera.translation().y(), 0.0),
                                        std::atan2(look.y(), look.x()));
  iv::SensorRig rig;
  iv::DepthCamera cam;
  cam.intrinsics = seq.intrinsics();
  cam.max_range = o.max_range;
  rig.add(cam, body.inverse() * camera, "recorded camera");
  iv::MobilePlannerParams pp;
  pp.gain.max_range = o.max_range;
  pp.start_free_radius = 1.0;    // the recording stands for the look-around: a hand-held camera has no rig blind
  pp.start_free_columns = true;  // zone to derive; whole columns within 1 m, as before
  iv::MobilePlanner planner(rig, pp);
  planner.plan(grid, body);  // the look-around, which the recording stands for
  const iv::MobilePlan plan = planner.plan(grid, body);
  if (plan.termination != iv::Termination::Running) {
    std::printf("next best view: none (%s)\n", std::string(iv::to_string(plan.termination)).c_str());
    return 0;
  }
  std::printf("next best view: (%.2f, %.2f) heading %.0f deg, gain %.1f (%.1f %% of an unknown world), %zu candidates, "
              "path %.2f m over %zu waypoints\n",
              plan.view.translation().x(), plan.view.translation().y(),
              std::atan2(plan.view.linear()(1, 0), plan.view.linear()(0, 0)) * 180.0 / std::numbers::pi, plan.gain,
              100.0 * plan.relative_gain, plan.considered, plan.path_length, plan.path.size());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  Options o;
  CLI::App app{"Intervox: replay a recorded depth sequence (TUM RGB-D layout) into a map, save it and ask the mobile\n"
               "planner for the next best view."};
  app.add_option("folder", o.folder, "sequence folder (depth/, depth.txt, groundtruth.txt)")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("--camera", o.camera, "intrinsics preset (docs/io.md)")
      ->check(CLI::IsMember({"tum-fr1", "tum-fr2", "tum-fr3", "kinect", "o3d100", "sim32"}))
      ->capture_default_str();
  app.add_option("--update", o.update, "update policy")
      ->check(CLI::IsMember({"bayes", "interval-lower", "interval-mean", "interval-upper", "compact-interval-mean"}))
      ->capture_default_str();
  app.add_option("--depth-factor", o.depth_factor, "PNG value per metre")
      ->check(examples::number_in(1e-6))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length in metres")
      ->check(examples::number_in(0.01, 0.5))
      ->capture_default_str();
  app.add_option("--max-range", o.max_range, "insertion and gain range in metres")
      ->check(examples::number_in(0.1, 50.0))
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  // Bad options: "replay: error: ..." and exit code 2; failures while running (a malformed
  // sequence, an output folder that cannot be written): the same line and exit code 1.
  return examples::cli_main("replay", app, argc, argv, [&] {
    std::map<std::string, std::function<int(const Options&)>> table;
    table["bayes"] = run<iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy>>;
    table["interval-lower"] = run<iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy>>;
    table["interval-mean"] = run<iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy>>;
    table["interval-upper"] = run<iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::MaxEntropy>>;
    table["compact-interval-mean"] = run<iv::VoxelGrid<iv::CompactIntervalUpdate<iv::MeanState>, iv::MaxEntropy>>;
    return table.at(o.update)(o);
  });
}
