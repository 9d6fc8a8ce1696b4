#pragma once
/// \file
/// Random apartments: a seed and options in, a world with its ground truth out. One to four rooms
/// of varied sizes joined by doorways (open, and now and then closed by a door), furniture against
/// the walls and standing free, and lying surfaces in a mix the options set: wall mirrors
/// (full-length and half-height, on any wall, outside walls included), mirror-fronted wardrobes
/// and cabinets (a mirror in front of a wall, not on it), a free-standing mirror, glass partitions,
/// glass doors, a glass window into another room, black (absorbing) furniture and polished-metal
/// panels. The worlds nobody tuned a planner on: docs/experiments.md ("Random apartments") runs
/// every planner over them against an oracle (make_oracle_rig()).
///
/// Every world is reachable: every room can be reached from the start by a round robot of
/// ApartmentOptions::robot_radius (plus a margin) through open doorways; the start stands clear of
/// everything. The truth knows every lying surface (Apartment::fixtures), the rooms, the doorways
/// and which space is real (Apartment::real_space()); Apartment::honest_twin() is the same
/// geometry with every surface diffuse.
///
/// Coordinates in metres, z up, the floor at z = 0, the apartment's free inside within
/// [0, width] x [0, depth]; walls, floor and ceiling are 0.1 m thick (interior walls centred on the
/// line between two rooms). Thread safety: make_apartment() shares no state; a built Apartment
/// is read-only afterwards (see Scene).

#include <intervox/core/error.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/random.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/apartment_parts.hpp>
#include <intervox/sim/detail/apartment_layout.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/scene.hpp>

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace intervox::sim {

/// A world of make_apartment() and its ground truth.
struct Apartment {
  Scene scene;
  std::uint64_t seed = 0;
  ApartmentOptions options;
  /// The free inside of every room (x-y between its walls' faces, z from 0 to the wall height).
  std::vector<Bounds> rooms;
  std::vector<ApartmentDoorway> doorways;
  /// The lying surfaces (and the furniture they belong to), in the order they were placed.
  std::vector<ApartmentFixture> fixtures;
  /// A free spot on the floor (z = 0), options.start_clearance from every obstacle.
  Point3 start = Point3::Zero();
  /// The room the start lies in (an index into rooms).
  int start_room = 0;
  /// The free inside of the outer walls: [0, width] x [0, depth] x [0, wall height].
  Bounds footprint;

  /// The robot's floor band over the footprint: z from \p low to \p high (the planners' default
  /// floor clearance and robot height), the region to give a planner or to score.
  Bounds band(double low = 0.2, double high = 0.8) const {
    return {{footprint.min.x(), footprint.min.y(), low}, {footprint.max.x(), footprint.max.y(), high}};
  }

  /// True if the world holds a fixture of \p kind.
  bool has(FixtureKind kind) const {
    return std::ranges::any_of(fixtures, [&](const ApartmentFixture& f) { return f.kind == kind; });
  }

  /// Every object whose surface lies (a mirror, glass, a black surface, polished metal): the
  /// fixtures' surfaces, sorted, without duplicates. What an oracle knows (make_oracle_rig()).
  std::vector<ObjectId> lying_objects() const {
    std::vector<ObjectId> out;
    for (const ApartmentFixture& f : fixtures) out.push_back(f.surface);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  /// The same geometry with every surface diffuse (Material::diffuse()): the world without lies.
  Scene honest_twin() const {
    Scene twin = scene;
    for (ObjectId i = 0; i < twin.size(); ++i)
      if (twin.material(i).surface != Surface::Diffuse) twin.set_material(i, Material::diffuse());
    return twin;
  }

  /// True if \p p is real space: inside a room or a doorway's opening, and inside no solid. Space
  /// behind a mirror (its phantom), inside a wall or inside furniture is not.
  /// \throws InvalidArgument for a non-finite point.
  bool real_space(const Point3& p) const {
    const bool in = std::ranges::any_of(rooms, [&](const Bounds& r) { return r.contains(p); }) ||
                    std::ranges::any_of(doorways, [&](const ApartmentDoorway& d) { return d.opening.contains(p); });
    return in && !scene.inside(p);
  }
};

/// The apartment of \p seed under \p options: the same seed and options give the same world on
/// every machine (the generator draws from SeededRandom only). See the file comment for what a
/// world holds and guarantees.
/// \throws InvalidArgument if the options do not validate; Error if no valid world is found in
///         64 attempts (options that leave no room, e.g. a door wider than a room).
inline Apartment make_apartment(std::uint64_t seed, const ApartmentOptions& options = {}) {
  options.validate();
  for (std::uint64_t attempt = 0; attempt < 64; ++attempt) {
    SeededRandom random(intervox::detail::mix64(seed + intervox::detail::kGamma * (attempt + 1)));
    detail::ApartmentLayout layout(options, random);
    if (!layout.generate()) continue;
    Apartment a;
    a.seed = seed;
    a.options = options;
    layout.build(a.scene, a.rooms, a.doorways, a.fixtures);
    a.start = layout.start();
    a.start_room = layout.start_room();
    a.footprint = layout.footprint();
    return a;
  }
  throw Error("intervox::sim::make_apartment: no valid apartment for seed " + std::to_string(seed) +
              " with these options in 64 attempts (rooms too small for the doors or the robot?)");
}

}  // namespace intervox::sim
