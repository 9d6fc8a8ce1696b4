// The planners on your own robot: a user-side exploration loop with its own sensor callback,
// using only the core, grid, raycast, map and plan layers (no simulator, no libpng). The "robot" here
// is a stand-in written by the user: a box-shaped room with a pillar, measured analytically. On a
// real robot, `sense` drives the base to the pose, grabs the cameras' depth images and returns
// them as beams in the world frame. Two robots explore it: the thesis' eight-camera base, and one
// forward camera on a differential drive; each counts its collisions with the room. Then the
// pillar turns black (it absorbs the light: its beams return nothing, so the insertion makes the
// pillar and the wall behind it free): the plain planner and the explained one (it drives only
// where returned, unrefuted beams explain free space) explore that room with the eight cameras.
// Their collisions are reported, not failed on: both meet the black pillar (the explained one
// keeps its centre off the pillar's unexplained columns, but unknown columns away from occupied
// ones do not narrow the map, so its body overlaps them). Last, the explained planner with the
// opt-in unexplained hazards (ExplainedPlanningParams::unexplained_hazards), which keeps its
// radius from them: a collision there fails the program. docs/planning.md, "Planning on explained
// free space", has the numbers and what the option costs in the lab room. Used by
// docs/planning.md ("using the planners on your robot").
#include <intervox/core/sensors.hpp>
#include <intervox/grid/named_grids.hpp>
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

/// The user's world: a 6 x 4 x 2.5 m room with a 0.6 m square pillar.
const iv::Point3 kRoomLo(0, 0, 0), kRoomHi(6, 4, 2.5), kPillarLo(3.2, 1.6, 0), kPillarHi(3.8, 2.2, 2.5);

/// Distance in the floor plane from (x, y) to the nearest obstacle of the world (walls, pillar).
double clearance(const iv::Point3& p) {
  const double wall = std::min({p.x() - kRoomLo.x(), kRoomHi.x() - p.x(), p.y() - kRoomLo.y(), kRoomHi.y() - p.y()});
  const double dx = std::max({kPillarLo.x() - p.x(), 0.0, p.x() - kPillarHi.x()});
  const double dy = std::max({kPillarLo.y() - p.y(), 0.0, p.y() - kPillarHi.y()});
  return std::min(wall, std::hypot(dx, dy));
}

/// One exploration of the world with \p rig: the loop of docs/planning.md. Returns the number of
/// places along the driven path (every 5 cm) where the base's 0.2 m inscribed disc meets a wall
/// or the pillar: the robot's own count of collisions against its own world.
int explore(const char* name, const iv::SensorRig& rig, const iv::MobilePlannerParams& params,
            bool black_pillar = false) {
  auto sense = [&](const iv::Pose& body) {
    std::vector<iv::Beam> beams;
    for (const iv::SensorRay& s : rig.rays(body)) {
      const iv::Ray& r = s.ray;
      const double wall = exit_distance(r.origin, r.direction, kRoomLo, kRoomHi);
      const double pillar = entry_distance(r.origin, r.direction, kPillarLo, kPillarHi);
      const double t = std::min(wall, pillar);
      if (t < s.min_range) continue;         // too close: an invalid pixel
      if (black_pillar && pillar <= wall) {  // the light is absorbed: no return, as a real camera reports it
        beams.push_back({r.origin, r.at(r.range), false});
        continue;
      }
      const bool hit = t <= r.range;
      beams.push_back({r.origin, r.at(std::min(t, r.range)), hit});
    }
    return beams;
  };

  // The planner and its map (the grid and, for the explained planner, the evidence it reads). The
  // region is left to the planner: it follows the observed space.
  iv::MobilePlanner planner(rig, params);
  iv::ExplainedMap<iv::IntervalGrid> map = planner.make_map(iv::IntervalGrid(0.1));
  std::printf("%s: %zu look-around scans, start taken as clear within %.2f m (the rig's blind zone)\n", name,
              planner.look_around_yaws().size(), planner.start_free_radius());

  iv::Pose pose = iv::planar_pose(iv::Point3(1.0, 1.0, 0.0), 0.0);
  double driven = 0;
  int collisions = 0;
  for (;;) {
    map.update_analysis();  // the analyses that change evidence, before planning (the explained planner's wall gaps)
    const iv::MobilePlan plan = planner.plan(map, pose);
    if (plan.termination != iv::Termination::Running) {
      std::printf("done: %s after %d views\n", std::string(iv::to_string(plan.termination)).c_str(), planner.steps());
      break;
    }
    for (const iv::Pose& waypoint : plan.path) {  // drive along the path (a real robot follows it)
      const iv::Point3 a = pose.translation(), b = waypoint.translation();
      const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.05)));
      for (int i = 1; i <= n; ++i) collisions += clearance(a + (b - a) * (double(i) / n)) < 0.2 ? 1 : 0;
      driven += (b - a).norm();
      pose = waypoint;
    }
    std::size_t beams = 0;
    for (const iv::Pose& scan : plan.scans) {  // sense at the view, turning on the spot
      pose = scan;
      const std::vector<iv::Beam> b = sense(pose);
      map.insert(std::span<const iv::Beam>(b));  // the grid, and the evidence the explained planner reads
      beams += b.size();
    }
    std::printf("view %2d (%s): at (%.2f, %.2f), gain %.0f (%.1f %% of an unknown world), %zu candidates, path %.2f m, "
                "%zu beams\n",
                planner.steps() - 1, std::string(iv::to_string(plan.reason)).c_str(), pose.translation().x(),
                pose.translation().y(), plan.gain, 100.0 * plan.relative_gain, plan.considered, plan.path_length,
                beams);
  }
  const iv::OccupancyCounts c = map.grid().counts();
  std::printf("map: %zu free, %zu occupied, %zu unknown voxels; %.1f m driven; collisions with the world: %d\n\n",
              c.free, c.occupied, c.unknown, driven, collisions);
  return collisions;
}

int robot_loop_main() {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  iv::MobilePlannerParams params;
  params.max_steps = 15;
  // What the planner needs: the sensors' description. First the thesis' base: eight ToF cameras.
  const int eight = explore("eight cameras (the thesis' base)", iv::SensorRig::mobile_base(), params);
  // Then a robot with one forward camera at knee height that can only drive forward (differential
  // drive): the look-around turns the full circle and the path turns on the spot at its corners.
  iv::SensorRig front;
  const iv::Point3 mount(0.3, 0.0, 0.5);
  front.add(iv::DepthCamera::o3d100(), iv::look_at(mount, mount + iv::Point3::UnitX()), "front");
  params.face_along_path = true;
  params.exact_blind_zone = true;  // the start rule walks the single camera's beams (docs/planning.md, "Any rig")
  const int one = explore("one forward camera, differential drive", front, params);
  // The black pillar, with both planners: reported, not failed on (see the file comment).
  params.face_along_path = false;
  params.exact_blind_zone = false;
  explore("black pillar, eight cameras, plain planner", iv::SensorRig::mobile_base(), params, true);
  params.explained.enabled = true;
  explore("black pillar, eight cameras, explained planner", iv::SensorRig::mobile_base(), params, true);
  params.explained.unexplained_hazards = true;
  const int hazards = explore("black pillar, eight cameras, explained planner with unexplained hazards",
                              iv::SensorRig::mobile_base(), params, true);
  return eight + one + hazards == 0 ? 0 : 1;  // these collisions with the robot's own world are failures
}
}  // namespace

// robot_loop takes no arguments: --help (or -h) prints what it does, anything else is a usage error.
int main(int argc, char** argv) {
  return examples::main_without_arguments(
      argc, argv, "robot_loop",
      "a planning loop in a room with a pillar measured by the user's own sensor callback, printed step by step: the "
      "thesis' eight-camera base, then one forward camera on a differential drive, then a black pillar under the plain "
      "and the explained planner (their collisions reported) and the explained planner with unexplained hazards; exit "
      "1 on a collision in the diffuse room or with the hazards",
      [] { return robot_loop_main(); });
}
