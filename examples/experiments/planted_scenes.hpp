#pragma once
// Planted scenes for the safe planner (issue 33's "Tests: planted scenes"), each a room the lab
// room is not, and one episode in them with the simulator's true scene as the oracle. Used by
// tests/plan/safe_planner_planted_test.cpp and examples/experiments/planted_scenes.cpp.
#include <intervox/eval/ground_truth.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/source.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace experiments {

namespace iv = intervox;

/// A planted scene: the world, a free spot for the base, the floor band scored, and what the user
/// gives the planner.
struct Planted {
  std::string name;
  iv::sim::Scene scene;
  iv::Point3 start;
  iv::Bounds scored;                             ///< the floor band of the room the robot starts in (scored)
  std::optional<iv::Bounds> region{};            ///< the region the user gives (none: derived, unbounded)
  std::vector<iv::PlanePatch> known_surfaces{};  ///< surfaces the user tells (ExplainedPlanningParams)
};

/// The floor band of the room [0, 5] x [0, 4] (the robot's height band, as MobilePlannerParams::region).
inline const iv::Bounds kRoomBand{{0.0, 0.0, 0.2}, {5.0, 4.0, 0.8}};

/// A room [0, 5] x [0, 4] x [0, 2.5] of diffuse 0.1 m walls, floor and ceiling; \p south_wall
/// false leaves the south wall to the caller, \p west_wall false the west wall.
inline void add_room(iv::sim::Scene& s, bool south_wall = true, bool west_wall = true) {
  const iv::sim::Material d = iv::sim::Material::diffuse();
  s.add_box({{-0.1, -0.1, -0.1}, {5.1, 4.1, 0.0}}, d, "floor");
  s.add_box({{-0.1, -0.1, 2.5}, {5.1, 4.1, 2.6}}, d, "ceiling");
  if (south_wall) s.add_box({{-0.1, -0.1, 0.0}, {5.1, 0.0, 2.5}}, d, "wall_south");
  s.add_box({{-0.1, 4.0, 0.0}, {5.1, 4.1, 2.5}}, d, "wall_north");
  if (west_wall) s.add_box({{-0.1, 0.0, 0.0}, {0.0, 4.0, 2.5}}, d, "wall_west");
  s.add_box({{5.0, 0.0, 0.0}, {5.1, 4.0, 2.5}}, d, "wall_east");
}

/// How the planner is told of the wall mirror's room.
enum class MirrorTold {
  Region,  ///< the room's region is given
  Wall,    ///< unbounded, the west wall's face told (ExplainedPlanningParams::known_surfaces)
  Nothing  ///< unbounded, nothing told
};

/// A mirror 2 m wide and 2 m high on the west wall, 1 mm before it: its phantom is a copy of the
/// room behind the wall.
inline Planted mirror_wall(MirrorTold told) {
  const char* names[] = {"mirror wall, the room's region", "mirror wall, unbounded, the wall told",
                         "mirror wall, unbounded, nothing told"};
  Planted p{names[static_cast<int>(told)], {}, {3.5, 2.0, 0.0}, kRoomBand};
  add_room(p.scene);
  p.scene.add_quad({0.001, 1.0, 0.0}, {0.0, 2.0, 0.0}, {0.0, 0.0, 2.0}, iv::sim::Material::mirror(), "mirror");
  if (told == MirrorTold::Wall)
    p.known_surfaces.push_back(iv::sim::box_face(iv::Bounds{{-0.1, 0.0, 0.0}, {0.0, 4.0, 2.5}}, 0, 0.0));
  else if (told == MirrorTold::Region)
    p.region = kRoomBand;
  return p;
}

/// A black box (0.8 x 1.2 m, 0.9 m high; 5 % of the beams return) 0.8 m before the west wall: the
/// beams that meet it mostly return nothing, and the wall behind it is seen past its sides;
/// unbounded.
inline Planted black_box() {
  Planted p{"black box, unbounded", {}, {3.5, 2.0, 0.0}, kRoomBand};
  add_room(p.scene);
  p.scene.add_box({{0.8, 1.4, 0.0}, {1.6, 2.6, 0.9}}, iv::sim::Material::absorbing(), "black_box");
  return p;
}

/// The two rooms of sim::make_symmetric_rooms() without their mirror: an open doorway 1 m wide in
/// the wall between them; unbounded.
inline Planted open_doorway() {
  iv::sim::SymmetricRooms r = iv::sim::make_symmetric_rooms();
  const iv::Bounds west = r.rooms[0];
  return {"open doorway (symmetric rooms), unbounded",
          std::move(r.scene),
          r.start,
          {{west.min.x(), west.min.y(), 0.2}, {west.max.x(), west.max.y(), 0.8}}};
}

/// The room with a doorway 1 m wide and 2 m high in the middle of its west wall (y in [1.5, 2.5])
/// into a room 6 m deep, with a crate 2.2-3.0 m beyond the doorway; unbounded.
inline Planted door_to_deep_room() {
  Planted p{"doorway to a deeper room, unbounded", {}, {3.5, 2.0, 0.0}, kRoomBand};
  iv::sim::Scene& s = p.scene;
  const iv::sim::Material d = iv::sim::Material::diffuse();
  add_room(s, true, false);
  s.add_box({{-6.1, -0.1, -0.1}, {-0.1, 4.1, 0.0}}, d, "floor_next");
  s.add_box({{-6.1, -0.1, 2.5}, {-0.1, 4.1, 2.6}}, d, "ceiling_next");
  s.add_box({{-6.1, -0.1, 0.0}, {-0.1, 0.0, 2.5}}, d, "wall_south_next");
  s.add_box({{-6.1, 4.0, 0.0}, {-0.1, 4.1, 2.5}}, d, "wall_north_next");
  s.add_box({{-6.1, 0.0, 0.0}, {-6.0, 4.0, 2.5}}, d, "wall_far");
  s.add_box({{-0.1, 0.0, 0.0}, {0.0, 1.5, 2.5}}, d, "wall_west_south");
  s.add_box({{-0.1, 2.5, 0.0}, {0.0, 4.0, 2.5}}, d, "wall_west_north");
  s.add_box({{-0.1, 1.5, 2.0}, {0.0, 2.5, 2.5}}, d, "lintel");
  s.add_box({{-3.0, 0.5, 0.0}, {-2.2, 1.2, 0.9}}, d, "crate_next");
  return p;
}

/// A glass pane (half the beams pass, refracted) in a window of the south wall, x in [2.0, 3.4],
/// z in [0.3, 1.6]; outside, a patch of ground, a crate 1.2 m out and a fence 3 m out; unbounded.
inline Planted glass_window() {
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

/// Every planted scene, in the order the program prints them.
inline std::vector<Planted> planted_scenes() {
  std::vector<Planted> out;
  for (const MirrorTold t : {MirrorTold::Region, MirrorTold::Wall, MirrorTold::Nothing}) out.push_back(mirror_wall(t));
  out.push_back(black_box());
  out.push_back(open_doorway());
  out.push_back(door_to_deep_room());
  out.push_back(glass_window());
  return out;
}

/// The safe-planner candidate (explained planning with unexplained and open-group hazards) on the
/// thesis' eight cameras, with what the user gives of \p planted; \p close_gaps adds
/// ExplainedPlanningParams::close_wall_gaps.
inline iv::MobilePlannerParams safe_params(const Planted& planted, std::uint64_t seed, unsigned threads = 1,
                                           bool close_gaps = true) {
  iv::MobilePlannerParams p;
  p.region = planted.region;
  p.explained.known_surfaces = planted.known_surfaces;
  p.seed = seed;
  p.threads = threads;
  p.max_steps = 30;
  p.explained.enabled = true;
  p.explained.unexplained_hazards = true;
  p.explained.open_group_hazards = true;
  p.explained.close_wall_gaps = close_gaps;
  return p;
}

/// What one episode did, against the true scene.
struct Outcome {
  iv::Termination termination = iv::Termination::Running;
  std::vector<iv::Pose> trajectory;
  std::vector<iv::ObjectCollisions> met;
  iv::PathCollisions collisions;
  double known = 0;             ///< the share of the scored room's reachable floor known (floor_coverage)
  std::size_t steps = 0;        ///< planning calls (the look-around and the one that ended the episode included)
  std::size_t gaps_closed = 0;  ///< wall gaps closed in the last plan (close_wall_gaps)
  std::size_t outside = 0;  ///< trajectory poses outside the scored room (x-y): through a doorway, or into a phantom
};

/// One episode in \p planted from its start with \p p, in an unbounded grid of \p resolution.
template <class Grid>
Outcome explore(const Planted& planted, const iv::MobilePlannerParams& p, std::uint64_t seed, double resolution = 0.1) {
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  iv::MobilePlanner planner(rig, p);
  auto map = planner.make_map(Grid(resolution));
  const Grid& grid = map.grid();
  iv::Episode episode(map, planner, iv::sim::SimulatedRig(planted.scene, rig, seed),
                      iv::planar_pose(planted.start, 0.0));
  Outcome o;
  o.termination = episode.run();
  o.trajectory = episode.trajectory();
  for (const iv::Pose& q : o.trajectory) {
    const iv::Point3 t = q.translation();
    o.outside += t.x() < planted.scored.min.x() || t.x() > planted.scored.max.x() || t.y() < planted.scored.min.y() ||
                         t.y() > planted.scored.max.y()
                     ? 1
                     : 0;
  }
  o.steps = episode.steps().size();
  if (!episode.steps().empty())
    for (const iv::WallGap& g : episode.steps().back().plan.wall_gaps) o.gaps_closed += g.opening ? 0 : 1;
  const double radius = p.map.keep_out();
  o.met = iv::collisions_by_object(planted.scene, grid.geometry(), o.trajectory, radius, p.floor_clearance,
                                   p.obstacle_height);
  o.known = iv::floor_coverage(grid, planted.scene, planted.scored, p.map, planted.start).known;
  o.collisions = iv::count_path_collisions(planted.scene, grid.geometry(), o.trajectory, radius, p.floor_clearance,
                                           p.obstacle_height);
  return o;
}

/// The names of the objects met, space-separated.
inline std::string met_names(const Outcome& o) {
  std::string s;
  for (const iv::ObjectCollisions& c : o.met) s += c.name + " ";
  return s;
}

}  // namespace experiments
