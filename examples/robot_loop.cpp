// The planners on your own robot: a user-side exploration loop with its own sensor callback,
// using only the core, grid, raycast and plan layers (no simulator, no libpng). The "robot" here
// is a stand-in written by the user: a box-shaped room with a pillar, measured analytically. On a
// real robot, `sense` drives the base to the pose, grabs the cameras' depth images and returns
// them as beams in the world frame. Used by docs/planning.md ("using the planners on your robot").
#include <intervox/core/sensors.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include "common/guarded_main.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <limits>
#include <span>
#include <vector>

namespace iv = intervox;

namespace {

/// Distance along the unit ray (o, d) to the inside walls of the box [lo, hi] (the ray starts inside).
double exit_distance(const iv::Point3& o, const iv::Point3& d, const iv::Point3& lo, const iv::Point3& hi) {
  double t = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 0) t = std::min(t, (hi[i] - o[i]) / d[i]);
    if (d[i] < 0) t = std::min(t, (lo[i] - o[i]) / d[i]);
  }
  return t;
}

/// Distance along the unit ray (o, d) to the solid box [lo, hi] (the slab method), or infinity.
double entry_distance(const iv::Point3& o, const iv::Point3& d, const iv::Point3& lo, const iv::Point3& hi) {
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0) {
      if (o[i] < lo[i] || o[i] > hi[i]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (lo[i] - o[i]) / d[i], b = (hi[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

}  // namespace

namespace {
int robot_loop_main() {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  // What the planner needs: the sensors' description (here the thesis' base: eight ToF cameras).
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  // The user's world: a 6 x 4 x 2.5 m room with a 0.6 m square pillar.
  const iv::Point3 room_lo(0, 0, 0), room_hi(6, 4, 2.5), pillar_lo(3.2, 1.6, 0), pillar_hi(3.8, 2.2, 2.5);
  auto sense = [&](const iv::Pose& body) {
    std::vector<iv::Beam> beams;
    for (const iv::SensorRay& s : rig.rays(body)) {
      const iv::Ray& r = s.ray;
      const double t = std::min(exit_distance(r.origin, r.direction, room_lo, room_hi),
                                entry_distance(r.origin, r.direction, pillar_lo, pillar_hi));
      if (t < s.min_range) continue;  // too close: an invalid pixel
      const bool hit = t <= r.range;
      beams.push_back({r.origin, r.at(std::min(t, r.range)), hit});
    }
    return beams;
  };

  // The map and the planner. The region is left to the planner: it follows the observed space.
  iv::IntervalGrid grid(0.1);
  iv::MobilePlannerParams params;
  params.max_steps = 15;
  iv::MobilePlanner planner(rig, params);
  iv::InsertOptions insert;
  insert.max_range = planner.max_range();

  iv::Pose pose = iv::planar_pose(iv::Point3(1.0, 1.0, 0.0), 0.0);
  double driven = 0;
  for (;;) {
    const iv::MobilePlan plan = planner.plan(grid, pose);
    if (plan.termination != iv::Termination::Running) {
      std::printf("done: %s after %d views\n", std::string(iv::to_string(plan.termination)).c_str(), planner.steps());
      break;
    }
    for (const iv::Pose& waypoint : plan.path) {  // drive along the path (a real robot follows it)
      driven += (waypoint.translation() - pose.translation()).norm();
      pose = waypoint;
    }
    std::size_t beams = 0;
    for (const iv::Pose& scan : plan.scans) {  // sense at the view, turning on the spot
      pose = scan;
      const std::vector<iv::Beam> b = sense(pose);
      iv::insert_beams(grid, std::span<const iv::Beam>(b), insert);
      beams += b.size();
    }
    std::printf("view %2d (%s): at (%.2f, %.2f), gain %.0f (%.1f %% of an unknown world), %zu candidates, path %.2f m, %zu beams\n",
                planner.steps() - 1, std::string(iv::to_string(plan.reason)).c_str(), pose.translation().x(),
                pose.translation().y(), plan.gain, 100.0 * plan.relative_gain, plan.considered, plan.path_length, beams);
  }
  const iv::OccupancyCounts c = grid.counts();
  std::printf("map: %zu free, %zu occupied, %zu unknown voxels; %.1f m driven\n", c.free, c.occupied, c.unknown, driven);
  return 0;
}
}  // namespace

// robot_loop takes no arguments: --help (or -h) prints what it does, anything else is a usage error.
int main(int argc, char** argv) {
  return examples::main_without_arguments(argc, argv, "robot_loop", "a planning loop of the mobile base in a simulated room with a pillar, printed step by step", [] { return robot_loop_main(); });
}
