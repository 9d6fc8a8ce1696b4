#pragma once
/// \file
/// Built-in scenes: the thesis' lab room (Fig. 5.2b) for the mobile base, two mirror-symmetric
/// rooms joined by a doorway (the hard case of mirror detection) and an object workcell for the
/// arm. Coordinates in metres, z up, floor at z = 0. See docs/platforms.md for maps.
/// Thread safety: the builders share no state; a built scene is read-only afterwards (see Scene).

#include <intervox/core/key.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/mesh.hpp>
#include <intervox/sim/scene.hpp>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace intervox::sim {

/// Options of the lab room.
struct LabRoomOptions {
  /// The closet against the west wall whose surface the experiments vary (thesis Fig. 5.2b, red).
  Material closet_material = Material::diffuse();
  /// The door in the east wall. The thesis made doors reflective in some runs (5.2.2):
  /// `Material::mirror()` here gives that reflective door, whose phantom copy of the room lies
  /// beyond the east wall.
  Material door_material = Material::diffuse();
  /// Everything else.
  Material default_material = Material::diffuse();
  /// Add the ceiling at z = 3 m (the cameras at knee height rarely reach it).
  bool ceiling = true;
  /// An open doorway in the east wall (y in [4.7, 5.9], 2.1 m high, no door leaf) to an annex
  /// room beyond it (inside [8.1, 11.1] x [3.5, 6.5] x [0, 3]) holding a shelf and a crate: space a
  /// planner must find through an opening, which no beam may call a lie. LabRoom::annex_interior.
  bool annex = false;
  /// A window without glass in the south wall (x in [5.0, 6.4], z in [0.3, 1.6]) with real things
  /// beyond it: a patch of ground, a crate 1.2 m outside and a fence 3 m outside. LabRoom::window.
  bool window = false;
  /// The closet of closet_material on its front only (the face towards the room, x = 0.601; a
  /// wardrobe with a mirror door): its body, sides and top keep default_material. Off: the whole
  /// closet has closet_material.
  bool closet_front_only = false;
};

/// The lab room and what a planner needs to know about it.
struct LabRoom {
  Scene scene;
  ObjectId closet = 0;  ///< the closet with LabRoomOptions::closet_material (its front quad with closet_front_only)
  ObjectId closet_body = 0;  ///< the closet's box (the same object as `closet` without closet_front_only)
  ObjectId door = 0;         ///< the door (a quad just in front of the east wall)
  /// The free inside of the room, [0, 8] x [0, 6] x [0, 3]; walls, floor and ceiling are 0.1 m
  /// thick boxes outside it (scene.bounds() includes them).
  Bounds interior{{0.0, 0.0, 0.0}, {8.0, 6.0, 3.0}};
  /// A free spot on the floor for the base (its footprint of 0.6 x 0.4 m fits in any yaw).
  Point3 start{6.0, 1.5, 0.0};
  /// With LabRoomOptions::annex: the free inside of the annex, and the doorway's opening (the
  /// gap in the east wall, x in [8.0, 8.1]).
  std::optional<Bounds> annex_interior, annex_doorway;
  /// With LabRoomOptions::window: the window's opening (the gap in the south wall, y in [-0.1, 0]).
  std::optional<Bounds> window;
};

/// An ~8 m x 6 m x 3 m robotics lab after the thesis' Fig. 5.2b: four walls, floor and ceiling;
/// a row of two desks along the south wall, a desk along the east wall and an island desk
/// (0.76 m high tops on four cylindrical legs); the closet against the west wall (material chosen
/// by the user), two closets along the north wall, a rolling cabinet standing at an angle (an
/// oriented box), two low barriers (0.4 m), a trash can (cylinder), a globe on the island desk
/// (sphere), and a door in the east wall (quad). Passages between obstacles are at least 1 m
/// wide and the free floor is connected.
/// \throws InvalidArgument if a material does not validate.
inline LabRoom make_lab_room(const LabRoomOptions& o = {}) {
  LabRoom lab;
  Scene& s = lab.scene;
  const Material& d = o.default_material;
  const auto box = [&](const char* name, Point3 lo, Point3 hi, const Material& m) {
    return s.add_box({lo, hi}, m, name);
  };
  box("floor", {-0.1, -0.1, -0.1}, {8.1, 6.1, 0.0}, d);
  if (o.ceiling) box("ceiling", {-0.1, -0.1, 3.0}, {8.1, 6.1, 3.1}, d);
  if (o.window) {
    // The south wall around the opening x in [5.0, 6.4], z in [0.3, 1.6]; outside, a patch of
    // ground, a crate and a fence (real things the beams through the window meet).
    const Bounds opening{{5.0, -0.1, 0.3}, {6.4, 0.0, 1.6}};
    box("wall_south", {-0.1, -0.1, 0.0}, {5.0, 0.0, 3.0}, d);
    box("wall_south_east", {6.4, -0.1, 0.0}, {8.1, 0.0, 3.0}, d);
    box("wall_south_sill", {5.0, -0.1, 0.0}, {6.4, 0.0, 0.3}, d);
    box("wall_south_lintel", {5.0, -0.1, 1.6}, {6.4, 0.0, 3.0}, d);
    box("ground_outside", {3.5, -3.2, -0.1}, {7.9, -0.1, 0.0}, d);
    box("crate_outside", {5.3, -1.8, 0.0}, {6.1, -1.2, 0.8}, d);
    box("fence_outside", {3.5, -3.2, 0.0}, {7.9, -3.1, 2.0}, d);
    lab.window = opening;
  } else {
    box("wall_south", {-0.1, -0.1, 0.0}, {8.1, 0.0, 3.0}, d);
  }
  box("wall_north", {-0.1, 6.0, 0.0}, {8.1, 6.1, 3.0}, d);
  box("wall_west", {-0.1, 0.0, 0.0}, {0.0, 6.0, 3.0}, d);
  if (o.annex) {
    // The east wall around the doorway y in [4.7, 5.9] (2.1 m high), and the annex beyond it.
    box("wall_east", {8.0, 0.0, 0.0}, {8.1, 4.7, 3.0}, d);
    box("wall_east_north", {8.0, 5.9, 0.0}, {8.1, 6.6, 3.0}, d);
    box("wall_east_lintel", {8.0, 4.7, 2.1}, {8.1, 5.9, 3.0}, d);
    box("annex_floor", {8.1, 3.4, -0.1}, {11.2, 6.6, 0.0}, d);
    if (o.ceiling) box("annex_ceiling", {8.1, 3.4, 3.0}, {11.2, 6.6, 3.1}, d);
    box("annex_wall_south", {8.1, 3.4, 0.0}, {11.2, 3.5, 3.0}, d);
    box("annex_wall_north", {8.1, 6.5, 0.0}, {11.2, 6.6, 3.0}, d);
    box("annex_wall_east", {11.1, 3.5, 0.0}, {11.2, 6.5, 3.0}, d);
    box("annex_shelf", {10.4, 3.5, 0.0}, {11.099, 4.6, 1.8}, d);
    box("annex_crate", {9.3, 5.4, 0.0}, {9.8, 5.9, 0.5}, d);
    lab.annex_interior = Bounds{{8.1, 3.5, 0.0}, {11.1, 6.5, 3.0}};
    lab.annex_doorway = Bounds{{8.0, 4.7, 0.0}, {8.1, 5.9, 2.1}};
  } else {
    box("wall_east", {8.0, 0.0, 0.0}, {8.1, 6.0, 3.0}, d);
  }
  lab.door = s.add_quad({7.999, 3.6, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 2.1}, o.door_material, "door");
  // 1 mm off the wall, so that a beam passing a transparent closet meets the wall behind it.
  if (o.closet_front_only) {
    // The body in the room's material, its front (towards the room) 1 mm before the body's face.
    lab.closet_body = box("closet", {0.001, 3.4, 0.0}, {0.601, 4.6, 2.0}, d);
    lab.closet = s.add_quad({0.602, 3.4, 0.0}, {0.0, 1.2, 0.0}, {0.0, 0.0, 2.0}, o.closet_material, "closet_front");
  } else {
    lab.closet = lab.closet_body = box("closet", {0.001, 3.4, 0.0}, {0.601, 4.6, 2.0}, o.closet_material);
  }
  box("closet_north_1", {1.0, 5.4, 0.0}, {2.2, 5.999, 2.0}, d);
  box("closet_north_2", {2.201, 5.4, 0.0}, {3.4, 5.999, 2.0}, d);
  const auto desk = [&](const std::string& name, double x0, double y0, double x1, double y1) {
    s.add_box({{x0, y0, 0.72}, {x1, y1, 0.76}}, d, name);
    int leg = 0;
    for (const double x : {x0 + 0.05, x1 - 0.05})
      for (const double y : {y0 + 0.05, y1 - 0.05})
        s.add_cylinder({x, y, 0.0}, {x, y, 0.72}, 0.025, d, name + "_leg_" + std::to_string(leg++));
  };
  desk("desk_south_1", 0.8, 0.001, 2.4, 0.8);
  desk("desk_south_2", 2.401, 0.001, 4.0, 0.8);
  desk("desk_east", 7.2, 1.4, 7.999, 3.0);
  desk("desk_island", 4.2, 2.6, 5.8, 3.4);
  Pose cabinet = Pose::Identity();
  cabinet.linear() = Eigen::AngleAxisd(0.349065850398865915, Point3::UnitZ()).toRotationMatrix();  // 20°
  cabinet.translation() = Point3(1.5, 2.4, 0.35);
  s.add_oriented_box(cabinet, {0.3, 0.25, 0.35}, d, "cabinet");
  box("barrier_1", {5.4, 4.6, 0.0}, {6.8, 4.7, 0.4}, d);
  box("barrier_2", {3.0, 1.9, 0.0}, {3.1, 3.3, 0.4}, d);
  s.add_cylinder({4.3, 0.3, 0.0}, {4.3, 0.3, 0.45}, 0.18, d, "trash_can");
  s.add_sphere({5.0, 3.0, 0.88}, 0.12, d, "globe");
  return lab;
}

/// The face of \p box at \p value along axis \p axis (0 x, 1 y, 2 z), over the box's extent along
/// the other two: a surface to tell a planner (ExplainedPlanningParams::known_surfaces).
inline PlanePatch box_face(const Bounds& box, int axis, double value) {
  PlanePatch p;
  p.normal = Point3::Unit(axis);
  p.center = 0.5 * (box.min + box.max);
  p.center[axis] = value;
  p.axis_u = PlanePatch::floor_axis(p.normal);
  const Point3 size = box.max - box.min;
  p.half_u = 0.5 * std::abs(size.dot(p.axis_u));
  p.half_v = 0.5 * std::abs(size.dot(p.axis_v()));
  return p;
}

/// The lab room's floor plan as a user of such a room would know it: the inner faces of its four
/// walls (and, with the annex, the annex's four), with the openings left out (the doorway to the
/// annex and the window stay open: walls around them are kept as separate rectangles, to be told
/// with MirrorMerge::Keep as ExplainedPlanningParams::known_surfaces does).
inline std::vector<PlanePatch> lab_floor_plan(const LabRoom& lab) {
  const Bounds& in = lab.interior;
  const double x0 = in.min.x(), x1 = in.max.x(), y0 = in.min.y(), y1 = in.max.y(), z0 = in.min.z(), z1 = in.max.z();
  const auto box = [](double ax, double ay, double az, double bx, double by, double bz) {
    return Bounds{{ax, ay, az}, {bx, by, bz}};
  };
  std::vector<PlanePatch> walls;
  walls.push_back(box_face(box(x0, y0, z0, x0, y1, z1), 0, x0));  // west
  walls.push_back(box_face(box(x0, y1, z0, x1, y1, z1), 1, y1));  // north
  if (lab.window) {                                               // south, around the window
    const Bounds& w = *lab.window;
    walls.push_back(box_face(box(x0, y0, z0, w.min.x(), y0, z1), 1, y0));
    walls.push_back(box_face(box(w.max.x(), y0, z0, x1, y0, z1), 1, y0));
    walls.push_back(box_face(box(w.min.x(), y0, z0, w.max.x(), y0, w.min.z()), 1, y0));
    walls.push_back(box_face(box(w.min.x(), y0, w.max.z(), w.max.x(), y0, z1), 1, y0));
  } else {
    walls.push_back(box_face(box(x0, y0, z0, x1, y0, z1), 1, y0));
  }
  if (lab.annex_interior && lab.annex_doorway) {  // east, around the doorway, and the annex
    const Bounds& d = *lab.annex_doorway;
    const Bounds& a = *lab.annex_interior;
    walls.push_back(box_face(box(x1, y0, z0, x1, d.min.y(), z1), 0, x1));
    walls.push_back(box_face(box(x1, d.max.y(), z0, x1, y1, z1), 0, x1));
    walls.push_back(box_face(box(x1, d.min.y(), d.max.z(), x1, d.max.y(), z1), 0, x1));
    const double ax = a.min.x();  // the annex's side of the wall with the doorway
    walls.push_back(box_face(box(ax, a.min.y(), a.min.z(), ax, d.min.y(), a.max.z()), 0, ax));
    walls.push_back(box_face(box(ax, d.max.y(), a.min.z(), ax, a.max.y(), a.max.z()), 0, ax));
    walls.push_back(box_face(box(ax, d.min.y(), d.max.z(), ax, d.max.y(), a.max.z()), 0, ax));
    walls.push_back(box_face(box(a.min.x(), a.min.y(), a.min.z(), a.max.x(), a.min.y(), a.max.z()), 1, a.min.y()));
    walls.push_back(box_face(box(a.min.x(), a.max.y(), a.min.z(), a.max.x(), a.max.y(), a.max.z()), 1, a.max.y()));
    walls.push_back(box_face(box(a.max.x(), a.min.y(), a.min.z(), a.max.x(), a.max.y(), a.max.z()), 0, a.max.x()));
  } else {
    walls.push_back(box_face(box(x1, y0, z0, x1, y1, z1), 0, x1));
  }
  return walls;
}

/// The lab room's surfaces of LabRoomOptions::closet_material, as a user who knows where the
/// mirror (or glass, or black panel) is would tell them: the closet's front, sides, top and back,
/// or its front alone with closet_front_only.
inline std::vector<PlanePatch> lab_closet_surfaces(const LabRoom& lab) {
  const Bounds b = lab.scene.object_bounds(lab.closet);
  if (lab.closet != lab.closet_body) return {box_face(b, 0, b.max.x())};  // the front quad
  return {box_face(b, 0, b.max.x()), box_face(b, 0, b.min.x()), box_face(b, 1, b.min.y()), box_face(b, 1, b.max.y()),
          box_face(b, 2, b.max.z())};
}

/// Options of the two mirror-symmetric rooms (make_symmetric_rooms()).
struct SymmetricRoomsOptions {
  /// A mirror panel in the shared wall beside the doorway, seen from the west room (off: the wall
  /// is plain there and the scene is exactly mirror-symmetric).
  bool mirror = false;
  /// The panel's material (a perfect mirror by default; Material::diffuse() gives a painted niche).
  Material mirror_material = Material::mirror();
  /// Everything else.
  Material default_material = Material::diffuse();
  /// Add the ceiling at z = 2.6 m.
  bool ceiling = true;
};

/// The two mirror-symmetric rooms and what a planner or a test needs to know about them.
struct SymmetricRooms {
  Scene scene;
  /// The free insides: the west room [0, 4] x [0, 4] x [0, 2.6] and the east room
  /// [4.2, 8.2] x [0, 4] x [0, 2.6]; outer walls, floor and ceiling are 0.1 m thick boxes outside
  /// them, the shared wall fills x in [4.0, 4.2].
  std::array<Bounds, 2> rooms{Bounds{{0.0, 0.0, 0.0}, {4.0, 4.0, 2.6}}, Bounds{{4.2, 0.0, 0.0}, {8.2, 4.0, 2.6}}};
  /// The doorway's opening through the shared wall: x in [4.0, 4.2], y in [0.6, 1.6], up to 2.1 m.
  Bounds doorway{{4.0, 0.6, 0.0}, {4.2, 1.6, 2.1}};
  /// The plane x = symmetry_x (the shared wall's mid-plane) about which the rooms are mirror images.
  double symmetry_x = 4.1;
  /// With SymmetricRoomsOptions::mirror: the panel (a quad in the symmetry plane x = 4.1,
  /// y in [2.2, 3.2], z in [0, 2.1]; its bounds have zero extent in x), its object id, and the
  /// niche before it (the west half of the wall cut away, x in [4.0, 4.1], the same y and z).
  std::optional<Bounds> mirror, niche;
  std::optional<ObjectId> mirror_object;
  /// A free spot on the floor of the west room for the mobile base (0.6 x 0.4 m, any yaw).
  Point3 start{2.0, 1.5, 0.0};

  /// The mirror image of \p p about the symmetry plane: (2 symmetry_x - x, y, z).
  Point3 reflect(const Point3& p) const noexcept { return {2.0 * symmetry_x - p.x(), p.y(), p.z()}; }
};

/// Two rooms of 4 x 4 x 2.6 m, mirror images of each other about the mid-plane x = 4.1 of the
/// 0.2 m wall they share, joined by a doorway in that wall (y in [0.6, 1.6], 2.1 m high, no door
/// leaf): the known hard case of mirror detection. The west room holds a shelf against the west
/// wall ([0.001, 0.4] x [2.4, 3.6], 1.8 m high), a table (top [1.4, 2.6] x [2.6, 3.4] at
/// 0.72-0.76 m on four cylindrical legs), a crate ([2.6, 3.1] x [0.3, 0.8], 0.5 m), a low cabinet
/// against the north wall ([3.0, 3.6] x [3.4, 3.999], 0.9 m) and a bin (a cylinder of radius
/// 0.15 m, 0.45 m high, at (0.5, 0.5)); the east room holds their mirror images (names "west_*"
/// and "east_*"; SymmetricRooms::reflect() maps one to the other).
///
/// With SymmetricRoomsOptions::mirror, the west half of the shared wall is cut away beside the
/// doorway over a doorway-sized patch (y in [2.2, 3.2], up to 2.1 m) and a mirror panel closes it
/// in the symmetry plane, 1 mm before the east half of the wall behind it. The niche's sides,
/// folded by the mirror, look like the doorway's full-thickness sides, and what the mirror shows
/// of the west room is exactly the east room (its mirror image): from inside the west room a beam
/// folded by the mirror ends where a real beam through the doorway into the east room could end.
/// Only what is not symmetric gives it away (the robot itself, SimOptions::body; the niche's
/// back in the east half of the wall).
/// \throws InvalidArgument if a material does not validate.
inline SymmetricRooms make_symmetric_rooms(const SymmetricRoomsOptions& o = {}) {
  o.mirror_material.validate();
  o.default_material.validate();
  SymmetricRooms r;
  Scene& s = r.scene;
  const Material& d = o.default_material;
  const double x2 = 2.0 * r.symmetry_x;  // x -> x2 - x mirrors the west room onto the east one
  const auto box = [&](const std::string& name, Point3 lo, Point3 hi) { return s.add_box({lo, hi}, d, name); };
  // A box of the west room and its mirror image in the east room.
  const auto pair = [&](const std::string& name, Point3 lo, Point3 hi) {
    box("west_" + name, lo, hi);
    box("east_" + name, {x2 - hi.x(), lo.y(), lo.z()}, {x2 - lo.x(), hi.y(), hi.z()});
  };
  const auto cylinder_pair = [&](const std::string& name, Point3 base, double height, double radius) {
    s.add_cylinder(base, base + Point3(0.0, 0.0, height), radius, d, "west_" + name);
    const Point3 mb(x2 - base.x(), base.y(), base.z());
    s.add_cylinder(mb, mb + Point3(0.0, 0.0, height), radius, d, "east_" + name);
  };
  box("floor", {-0.1, -0.1, -0.1}, {8.3, 4.1, 0.0});
  if (o.ceiling) box("ceiling", {-0.1, -0.1, 2.6}, {8.3, 4.1, 2.7});
  box("wall_south", {-0.1, -0.1, 0.0}, {8.3, 0.0, 2.6});
  box("wall_north", {-0.1, 4.0, 0.0}, {8.3, 4.1, 2.6});
  pair("wall", {-0.1, 0.0, 0.0}, {0.0, 4.0, 2.6});  // west_wall and its image east_wall
  // The shared wall x in [4.0, 4.2] around the doorway y in [0.6, 1.6] (2.1 m high).
  box("shared_wall_south", {4.0, 0.0, 0.0}, {4.2, 0.6, 2.6});
  box("doorway_lintel", {4.0, 0.6, 2.1}, {4.2, 1.6, 2.6});
  box("shared_wall_middle", {4.0, 1.6, 0.0}, {4.2, 2.2, 2.6});
  if (o.mirror) {
    // The panel first, in the symmetry plane; the east half of the wall 1 mm behind it.
    r.mirror_object =
        s.add_quad({r.symmetry_x, 2.2, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 2.1}, o.mirror_material, "mirror");
    box("mirror_backing", {r.symmetry_x + 0.001, 2.2, 0.0}, {4.2, 3.2, 2.1});
    r.mirror = s.object_bounds(*r.mirror_object);
    r.niche = Bounds{{4.0, 2.2, 0.0}, {r.symmetry_x, 3.2, 2.1}};
  } else {
    box("shared_wall_panel", {4.0, 2.2, 0.0}, {4.2, 3.2, 2.1});
  }
  box("panel_lintel", {4.0, 2.2, 2.1}, {4.2, 3.2, 2.6});
  box("shared_wall_north", {4.0, 3.2, 0.0}, {4.2, 4.0, 2.6});
  // The furniture of the west room, each piece with its mirror image in the east room.
  pair("shelf", {0.001, 2.4, 0.0}, {0.4, 3.6, 1.8});
  pair("table_top", {1.4, 2.6, 0.72}, {2.6, 3.4, 0.76});
  int leg = 0;
  for (const double x : {1.45, 2.55})
    for (const double y : {2.65, 3.35}) cylinder_pair("table_leg_" + std::to_string(leg++), {x, y, 0.0}, 0.72, 0.025);
  pair("crate", {2.6, 0.3, 0.0}, {3.1, 0.8, 0.5});
  pair("cabinet", {3.0, 3.4, 0.0}, {3.6, 3.999, 0.9});
  cylinder_pair("bin", {0.5, 0.5, 0.0}, 0.45, 0.15);
  return r;
}

/// Options of the object workcell.
struct WorkcellOptions {
  /// The ring-shaped mechanical part: polished metal by default (Material::polished_metal(), as
  /// in the thesis' Fig. 5.16b): a direct return near normal incidence, mirror reflection beyond.
  Material part_material = Material::polished_metal();
  /// The bottle (transparent by default, Fig. 5.16a).
  Material bottle_material = Material::transparent();
  /// The box.
  Material box_material = Material::diffuse();
  /// Table, floor and backdrop.
  Material default_material = Material::diffuse();
  /// Facets around the ring mesh (>= 3).
  int ring_segments = 48;
};

/// The workcell and what an arm planner needs to know about it.
struct Workcell {
  Scene scene;
  ObjectId part = 0;         ///< the ring (a closed triangle mesh)
  ObjectId bottle = 0;       ///< the bottle's body (cylinder)
  ObjectId bottle_neck = 0;  ///< the bottle's neck (cylinder, same material)
  ObjectId box = 0;          ///< the box (an oriented box)
  ObjectId table = 0;        ///< the table top
  /// Centre of the table top's surface, where the objects stand (0.75, 0.75, 0.74).
  Point3 table_center{0.75, 0.75, 0.74};
  /// A box around the three objects (for sampling viewpoints and for metrics).
  Bounds objects{{0.4, 0.4, 0.74}, {1.1, 1.1, 1.04}};

  /// The box an arm models for one object ("part", "bottle" with its neck, or "box"): the object's
  /// bounds grown by \p margin on every side, from the table top up.
  /// \throws InvalidArgument for an unknown name or a negative / non-finite margin.
  Bounds object_region(std::string_view object, double margin) const {
    ParamCheck("intervox::sim::Workcell::object_region").nonnegative("margin", margin);
    Bounds b;
    if (object == "part") {
      b = scene.object_bounds(part);
    } else if (object == "box") {
      b = scene.object_bounds(box);
    } else if (object == "bottle") {
      b = scene.object_bounds(bottle);
      const Bounds& n = scene.object_bounds(bottle_neck);
      b = {b.min.cwiseMin(n.min), b.max.cwiseMax(n.max)};
    } else {
      ParamCheck("intervox::sim::Workcell::object_region")
          .fail("unknown object '" + std::string(object) + "' (part, bottle, box)");
    }
    b.min -= Point3::Constant(margin);
    b.max += Point3::Constant(margin);
    b.min.z() = table_center.z();
    return b;
  }
};

/// A ~1.5 m cube workcell for the arm: floor, a 0.9 m square table (0.74 m high, four legs), a
/// backdrop quad at y = 1.5 m (where the thesis saw the laser line on the wall behind the object),
/// and on the table a ring-shaped part with a central hole (outer radius 8 cm, inner 3 cm, 3 cm
/// high, at the table centre), a bottle (radius 3.5 cm, 22 cm body and a 6 cm neck) and a box
/// (12 x 8 x 10 cm, turned 25°).
/// \throws InvalidArgument if a material does not validate or ring_segments < 3.
inline Workcell make_workcell(const WorkcellOptions& o = {}) {
  Workcell w;
  Scene& s = w.scene;
  const Material& d = o.default_material;
  s.add_box({{0.0, 0.0, -0.02}, {1.5, 1.5, 0.0}}, d, "floor");
  w.table = s.add_box({{0.3, 0.3, 0.70}, {1.2, 1.2, 0.74}}, d, "table");
  int leg = 0;
  for (const double x : {0.35, 1.15})
    for (const double y : {0.35, 1.15})
      s.add_cylinder({x, y, 0.0}, {x, y, 0.70}, 0.03, d, "table_leg_" + std::to_string(leg++));
  s.add_quad({0.0, 1.5, 0.0}, {1.5, 0.0, 0.0}, {0.0, 0.0, 1.5}, d, "backdrop");
  w.part = s.add_mesh(make_ring({0.75, 0.75, 0.74}, 0.03, 0.08, 0.03, o.ring_segments), o.part_material, "part");
  w.bottle = s.add_cylinder({0.95, 0.55, 0.74}, {0.95, 0.55, 0.96}, 0.035, o.bottle_material, "bottle");
  w.bottle_neck = s.add_cylinder({0.95, 0.55, 0.96}, {0.95, 0.55, 1.02}, 0.013, o.bottle_material, "bottle_neck");
  Pose bp = Pose::Identity();
  bp.linear() = Eigen::AngleAxisd(0.436332312998582394, Point3::UnitZ()).toRotationMatrix();  // 25°
  bp.translation() = Point3(0.52, 0.95, 0.79);
  w.box = s.add_oriented_box(bp, {0.06, 0.04, 0.05}, o.box_material, "box");
  return w;
}

}  // namespace intervox::sim
