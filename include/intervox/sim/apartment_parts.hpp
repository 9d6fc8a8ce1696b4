#pragma once
/// \file
/// The parts of a random apartment (sim/apartment.hpp) that its ground truth names: the kinds of
/// lying surfaces (fixtures), doorways and their state, and the generator's options.
/// Thread safety: value types.

#include <intervox/core/key.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/scene.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace intervox::sim {

/// A lying surface of an apartment, by what it is in the world.
enum class FixtureKind : std::uint8_t {
  WallMirror = 0,      ///< a full-length mirror on a wall (from the floor to about 1.9 m)
  HalfMirror = 1,      ///< a half-height mirror on a wall (its lower edge 0.8-1.1 m up)
  MirrorWardrobe = 2,  ///< a wardrobe whose front is a mirror, 0.6 m in front of the wall
  MirrorCabinet = 3,   ///< a low cabinet (0.8-1 m) whose front is a mirror, 0.45 m in front of the wall
  FreeMirror = 4,      ///< a free-standing mirror (both faces), at any yaw, away from the walls
  GlassPartition = 5,  ///< a glass pane from the floor to 2 m, standing out from a wall into the room
  GlassDoor = 6,       ///< a doorway closed by a glass pane
  GlassWindow = 7,     ///< a glass window in a wall between two rooms
  BlackFurniture = 8,  ///< a sofa, cabinet or wardrobe with an absorbing surface (5 % of beams return)
  MetalPanel = 9,      ///< a polished-metal panel on a wall
};
/// Number of fixture kinds.
inline constexpr std::size_t kFixtureKinds = 10;

/// Name of a fixture kind ("wall-mirror", "half-mirror", "mirror-wardrobe", "mirror-cabinet",
/// "free-mirror", "glass-partition", "glass-door", "glass-window", "black-furniture",
/// "metal-panel").
constexpr std::string_view to_string(FixtureKind k) noexcept {
  constexpr std::array<std::string_view, kFixtureKinds> names{
      "wall-mirror",     "half-mirror", "mirror-wardrobe", "mirror-cabinet",  "free-mirror",
      "glass-partition", "glass-door",  "glass-window",    "black-furniture", "metal-panel"};
  const auto i = static_cast<std::size_t>(k);
  return i < kFixtureKinds ? names[i] : std::string_view("unknown");
}

/// A lying surface of an apartment and what it belongs to.
struct ApartmentFixture {
  FixtureKind kind = FixtureKind::WallMirror;
  ObjectId surface = 0;               ///< the object whose material lies (a mirror quad, a pane, a black box)
  std::optional<ObjectId> body{};     ///< the furniture it is the front of (mirror wardrobes and cabinets)
  int room = 0;                       ///< the room it stands in (a glass door or window: the first of its two)
  Bounds bounds;                      ///< the surface object's bounds
  std::optional<PlanePatch> plane{};  ///< the surface's plane, for planar fixtures (mirrors, panes, panels)
};

/// How a doorway between two rooms is closed.
enum class DoorwayState : std::uint8_t {
  Open = 0,    ///< no door leaf: the robot may pass
  Closed = 1,  ///< a (diffuse) door leaf fills it
  Glass = 2,   ///< a glass pane fills it (FixtureKind::GlassDoor)
};

/// Name of a doorway state ("open", "closed", "glass").
constexpr std::string_view to_string(DoorwayState s) noexcept {
  return s == DoorwayState::Closed ? "closed" : s == DoorwayState::Glass ? "glass" : "open";
}

/// A doorway through the wall between two rooms.
struct ApartmentDoorway {
  Bounds opening;  ///< the gap in the wall: the wall's thickness across, the doorway's width along it, z from 0
  DoorwayState state = DoorwayState::Open;
  std::array<int, 2> rooms{0, 0};  ///< the rooms it joins (indices into Apartment::rooms)
  std::optional<ObjectId> leaf{};  ///< the door leaf or pane, if any
  bool tree = false;               ///< one of the doorways that make every room reachable (always open)
};

/// Options of make_apartment(). The defaults give worlds of 15-80 m² in which each fixture kind
/// appears in about a third of the worlds.
struct ApartmentOptions {
  int min_rooms = 1;            ///< in [1, 4]
  int max_rooms = 4;            ///< in [min_rooms, 4]
  double max_area = 80.0;       ///< m², the most floor (the free inside of the outer walls), in [20, 400]
  double room_area_min = 12.0;  ///< m², a room's drawn area, > 0
  double room_area_max = 22.0;  ///< m², >= room_area_min
  double wall_height = 2.5;     ///< m, in [2.2, 4]
  double door_width_min = 1.0;  ///< m, >= 2 (robot_radius + margin) + 0.2 so that doors stay passable
  double door_width_max = 1.2;  ///< m, >= door_width_min
  double door_height = 2.05;    ///< m, in [1.5, wall_height)
  /// For every further wall piece two rooms share beyond the doorway that joins them: the chance
  /// of a further doorway there (open, or closed by a door: closed_door_share of them).
  double extra_door_probability = 0.4;
  double closed_door_share = 0.5;  ///< in [0, 1]
  /// The chance that a world holds each fixture kind (FixtureKind order), each in [0, 1]; a kind
  /// drawn but without room for it in that world is left out (Apartment::fixtures tells).
  std::array<double, kFixtureKinds> mix{0.35, 0.35, 0.35, 0.35, 0.35, 0.35, 0.35, 0.35, 0.35, 0.35};
  int min_furniture = 1;  ///< plain (diffuse) pieces per room, >= 0
  int max_furniture = 4;  ///< >= min_furniture
  /// The robot the worlds stay passable for: every room reachable by a disk of robot_radius +
  /// passage_margin (the planners' default robot radius is 0.35 m), m, >= 0.
  double robot_radius = 0.35;
  double passage_margin = 0.05;
  /// m; the start's distance to the nearest obstacle, >= robot_radius.
  double start_clearance = 0.8;

  /// \throws InvalidArgument naming the first option outside its range.
  void validate() const {
    const ParamCheck check("intervox::sim::ApartmentOptions");
    check.in_range("min_rooms", min_rooms, 1, 4);
    check.in_range("max_rooms", max_rooms, min_rooms, 4);
    check.in_range("max_area", max_area, 20.0, 400.0);
    check.positive("room_area_min", room_area_min);
    check.at_least("room_area_max", room_area_max, room_area_min);
    check.in_range("wall_height", wall_height, 2.2, 4.0);
    check.nonnegative("robot_radius", robot_radius);
    check.nonnegative("passage_margin", passage_margin);
    check.at_least("door_width_min", door_width_min, 2.0 * (robot_radius + passage_margin) + 0.2);
    check.at_least("door_width_max", door_width_max, door_width_min);
    check.in_range("door_height", door_height, 1.5, wall_height, RangeEnds::ClosedOpen);
    check.in_range("extra_door_probability", extra_door_probability, 0.0, 1.0);
    check.in_range("closed_door_share", closed_door_share, 0.0, 1.0);
    for (const double p : mix) check.in_range("mix", p, 0.0, 1.0);
    check.at_least("min_furniture", min_furniture, 0);
    check.at_least("max_furniture", max_furniture, min_furniture);
    check.at_least("start_clearance", start_clearance, robot_radius);
  }
};

}  // namespace intervox::sim
