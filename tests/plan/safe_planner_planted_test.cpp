// The safe-planner candidate (explained planning with unexplained and open-group hazards,
// docs/planning.md "Which options, as measured over 40 seeds") in four planted scenes, each a room
// the lab room is not: a mirror on a wall, a black box with a wall behind it, an open doorway to a
// second room, and a glass window with real things outside. The black box, the doorway and the
// window are explored in an unbounded grid whose region the planner derives from what it saw; the
// mirror with the region the user gives (the room), and in an unbounded grid with its wall told
// (ExplainedPlanningParams::known_surfaces). For each, the simulator's true scene is the oracle: no
// pose of the driven trajectory and no segment between two poses comes within the robot's radius
// (plus the map's clearance) of a true obstacle, the episode ends before its step budget, and at
// least 90 % of the reachable floor of the room it started in is known. What these cases leave out
// is measured in docs/planning.md ("Planted scenes"): in an unbounded grid with nothing told, the
// candidate drives through the wall mirror.
#include <catch2/catch.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/source.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {

/// A planted scene: the world and a free spot for the base.
struct Planted {
  std::string name;
  iv::sim::Scene scene;
  iv::Point3 start;
  iv::Bounds scored;                             ///< the floor band of the room the robot starts in (scored)
  std::optional<iv::Bounds> region{};            ///< the region the user gives (none: derived, unbounded)
  std::vector<iv::PlanePatch> known_surfaces{};  ///< surfaces the user tells (ExplainedPlanningParams)
};

/// The floor band of the room [0, 5] x [0, 4] (the robot's height band, as MobilePlannerParams::region).
const iv::Bounds kRoomBand{{0.0, 0.0, 0.2}, {5.0, 4.0, 0.8}};

/// A room [0, 5] x [0, 4] x [0, 2.5] of diffuse 0.1 m walls, floor and ceiling; \p south_wall
/// false leaves the south wall to the caller.
void add_room(iv::sim::Scene& s, bool south_wall = true) {
  const iv::sim::Material d = iv::sim::Material::diffuse();
  s.add_box({{-0.1, -0.1, -0.1}, {5.1, 4.1, 0.0}}, d, "floor");
  s.add_box({{-0.1, -0.1, 2.5}, {5.1, 4.1, 2.6}}, d, "ceiling");
  if (south_wall) s.add_box({{-0.1, -0.1, 0.0}, {5.1, 0.0, 2.5}}, d, "wall_south");
  s.add_box({{-0.1, 4.0, 0.0}, {5.1, 4.1, 2.5}}, d, "wall_north");
  s.add_box({{-0.1, 0.0, 0.0}, {0.0, 4.0, 2.5}}, d, "wall_west");
  s.add_box({{5.0, 0.0, 0.0}, {5.1, 4.0, 2.5}}, d, "wall_east");
}

/// A mirror 2 m wide and 2 m high on the west wall, 1 mm before it: its phantom is a copy of the
/// room behind the wall.
/// \p told: in an unbounded grid with the west wall's face told; otherwise with the room's region.
Planted mirror_wall(bool told) {
  Planted p{told ? "mirror wall, unbounded, the wall told" : "mirror wall, the room's region", {}, {3.5, 2.0, 0.0}, kRoomBand};
  add_room(p.scene);
  p.scene.add_quad({0.001, 1.0, 0.0}, {0.0, 2.0, 0.0}, {0.0, 0.0, 2.0}, iv::sim::Material::mirror(), "mirror");
  if (told)
    p.known_surfaces.push_back(iv::sim::box_face(iv::Bounds{{-0.1, 0.0, 0.0}, {0.0, 4.0, 2.5}}, 0, 0.0));
  else
    p.region = kRoomBand;
  return p;
}

/// A black box (0.8 x 1.2 m, 0.9 m high; 5 % of the beams return) 0.8 m before the west wall: the
/// beams that meet it mostly return nothing, and the wall behind it is seen past its sides;
/// unbounded.
Planted black_box() {
  Planted p{"black box, unbounded", {}, {3.5, 2.0, 0.0}, kRoomBand};
  add_room(p.scene);
  p.scene.add_box({{0.8, 1.4, 0.0}, {1.6, 2.6, 0.9}}, iv::sim::Material::absorbing(), "black_box");
  return p;
}

/// The two rooms of sim::make_symmetric_rooms() without their mirror: an open doorway 1 m wide in
/// the wall between them; unbounded.
Planted open_doorway() {
  iv::sim::SymmetricRooms r = iv::sim::make_symmetric_rooms();
  const iv::Bounds west = r.rooms[0];
  return {"open doorway, unbounded", std::move(r.scene), r.start, {{west.min.x(), west.min.y(), 0.2}, {west.max.x(), west.max.y(), 0.8}}};
}

/// A glass pane (half the beams pass, refracted) in a window of the south wall, x in [2.0, 3.4],
/// z in [0.3, 1.6]; outside, a patch of ground, a crate 1.2 m out and a fence 3 m out; unbounded.
Planted glass_window() {
  Planted p{"glass window, unbounded", {}, {2.5, 2.0, 0.0}, kRoomBand};
  add_room(p.scene, false);
  iv::sim::Scene& s = p.scene;
  const iv::sim::Material d = iv::sim::Material::diffuse();
  s.add_box({{-0.1, -0.1, 0.0}, {2.0, 0.0, 2.5}}, d, "wall_south");
  s.add_box({{3.4, -0.1, 0.0}, {5.1, 0.0, 2.5}}, d, "wall_south_east");
  s.add_box({{2.0, -0.1, 0.0}, {3.4, 0.0, 0.3}}, d, "sill");
  s.add_box({{2.0, -0.1, 1.6}, {3.4, 0.0, 2.5}}, d, "lintel");
  s.add_quad({2.0, -0.05, 0.3}, {1.4, 0.0, 0.0}, {0.0, 0.0, 1.3}, iv::sim::Material::transparent(), "glass");
  s.add_box({{0.5, -3.2, -0.1}, {4.9, -0.1, 0.0}}, d, "ground_outside");
  s.add_box({{2.3, -1.8, 0.0}, {3.1, -1.2, 0.8}}, d, "crate_outside");
  s.add_box({{0.5, -3.2, 0.0}, {4.9, -3.1, 2.0}}, d, "fence_outside");
  return p;
}

/// The safe-planner candidate on the thesis' eight cameras, with what the user gives of \p planted.
iv::MobilePlannerParams safe_params(const Planted& planted, std::uint64_t seed, unsigned threads = 1) {
  iv::MobilePlannerParams p;
  p.region = planted.region;
  p.explained.known_surfaces = planted.known_surfaces;
  p.seed = seed;
  p.threads = threads;
  p.max_steps = 30;
  p.explained.enabled = true;
  p.explained.unexplained_hazards = true;
  p.explained.open_group_hazards = true;
  return p;
}

struct Outcome {
  iv::Termination termination = iv::Termination::Running;
  std::vector<iv::Pose> trajectory;
  std::vector<iv::ObjectCollisions> met;
  iv::PathCollisions collisions;
  double known = 0;  ///< the share of the scored room's reachable floor known (floor_coverage)
};

/// One episode in \p planted from its start with the candidate, in an unbounded grid of 10 cm voxels.
template <class Grid>
Outcome explore(const Planted& planted, std::uint64_t seed, unsigned threads = 1) {
  Grid grid(0.1);
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  const iv::MobilePlannerParams p = safe_params(planted, seed, threads);
  iv::MobilePlanner planner(rig, p);
  iv::Episode episode(grid, planner, iv::sim::SimulatedRig(planted.scene, rig, seed), iv::planar_pose(planted.start, 0.0));
  Outcome o;
  o.termination = episode.run();
  o.trajectory = episode.trajectory();
  const double radius = p.map.keep_out();
  o.met = iv::collisions_by_object(planted.scene, grid.geometry(), o.trajectory, radius, p.floor_clearance, p.obstacle_height);
  o.known = iv::floor_coverage(grid, planted.scene, planted.scored, p.map, planted.start).known;
  o.collisions = iv::count_path_collisions(planted.scene, grid.geometry(), o.trajectory, radius, p.floor_clearance, p.obstacle_height);
  return o;
}

std::string met_names(const Outcome& o) {
  std::string s;
  for (const iv::ObjectCollisions& c : o.met) s += c.name + " ";
  return s;
}

}  // namespace

TEMPLATE_TEST_CASE("the safe-planner candidate never drives into a planted mirror, black box, doorway frame or window, and "
                   "its episode ends",
                   "[plan][explained][hazard][episode][slow]", iv::IntervalGrid, iv::BayesGrid) {
  for (const Planted& planted : {mirror_wall(false), mirror_wall(true), black_box(), open_doorway(), glass_window()}) {
    CAPTURE(planted.name);
    const Outcome o = explore<TestType>(planted, 1);
    CAPTURE(iv::to_string(o.termination), o.trajectory.size(), o.known, met_names(o));
    CHECK(o.trajectory.size() > 1);  // it drove
    CHECK(o.known >= 0.9);           // and it explored the room it started in
    CHECK(o.collisions.poses == 0);
    CHECK(o.collisions.segments == 0);
    CHECK(o.met.empty());
    CHECK(o.termination != iv::Termination::Budget);
    CHECK(o.termination != iv::Termination::Running);
  }
}

TEST_CASE("the safe-planner candidate drives the same trajectory in a planted scene on one thread and on two",
          "[plan][explained][hazard][episode][threaded][slow]") {
  const Planted planted = mirror_wall(false);
  const Outcome one = explore<iv::IntervalGrid>(planted, 3, 1);
  const Outcome two = explore<iv::IntervalGrid>(planted, 3, 2);
  CHECK(one.termination == two.termination);
  REQUIRE(one.trajectory.size() == two.trajectory.size());
  REQUIRE(one.trajectory.size() > 1);
  for (std::size_t i = 0; i < one.trajectory.size(); ++i) CHECK(one.trajectory[i].isApprox(two.trajectory[i], 0.0));
}
