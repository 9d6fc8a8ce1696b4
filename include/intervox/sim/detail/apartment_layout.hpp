#pragma once
/// \file
/// Internal: how make_apartment() (sim/apartment.hpp) draws a world, in stages: the floor plan
/// (rooms split from a rectangle, joined by doorways: FloorPlan), the openings and lying surfaces
/// (Furnishing), and the plain furniture, each piece placed only where it leaves every room
/// reachable for the robot (Placer); then the start. Not public API.

#include <intervox/core/random.hpp>
#include <intervox/sim/apartment_parts.hpp>
#include <intervox/sim/detail/apartment_draw.hpp>
#include <intervox/sim/detail/apartment_floor_plan.hpp>
#include <intervox/sim/detail/apartment_furnishing.hpp>
#include <intervox/sim/detail/apartment_placer.hpp>
#include <intervox/sim/scene.hpp>

#include <optional>
#include <vector>

namespace intervox::sim::detail {

/// One draw of an apartment: generate() plans it and says whether the draw gave a valid world;
/// build() adds the planned objects to a Scene and fills the truth.
class ApartmentLayout {
 public:
  ApartmentLayout(const ApartmentOptions& o, SeededRandom& random)
      : o_(o), draws_(random), plan_(o, draws_), furnishing_(o, draws_, plan_) {}

  /// Plans the world; false if this draw gave none (make_apartment() then draws again).
  bool generate() {
    if (!plan_.draw()) return false;
    plan_.add_further_doorways();
    furnishing_.glass_openings();
    Placer placer(plan_, draws_, o_.robot_radius + o_.passage_margin);
    if (!placer.rooms_reachable(placer.raster())) return false;
    furnishing_.fixtures(placer);
    furnishing_.furniture(placer);
    const std::optional<Point3> s = placer.start(o_.start_clearance, start_room_);
    if (s) start_ = *s;
    return s.has_value();
  }

  /// The free inside of the outer walls.
  Bounds footprint() const { return {{0.0, 0.0, 0.0}, {plan_.width(), plan_.depth(), o_.wall_height}}; }
  Point3 start() const { return start_; }
  int start_room() const { return start_room_; }

  /// Adds the planned objects to \p scene (floor, ceiling and walls first) and fills the truth.
  void build(Scene& scene, std::vector<Bounds>& rooms, std::vector<ApartmentDoorway>& doorways,
             std::vector<ApartmentFixture>& fixtures) const {
    std::vector<ObjectSpec> all = plan_.structure();
    all.insert(all.end(), furnishing_.objects().begin(), furnishing_.objects().end());
    rooms = plan_.rooms();
    doorways = plan_.doorways();
    fixtures = furnishing_.fixtures();
    for (const ObjectSpec& s : all) {
      const ObjectId id = add_object(scene, s);
      if (s.fixture >= 0) {
        ApartmentFixture& f = fixtures[static_cast<std::size_t>(s.fixture)];
        if (s.fixture_body) {
          f.body = id;
        } else {
          f.surface = id;
          f.bounds = scene.object_bounds(id);
        }
      }
      if (s.doorway >= 0) doorways[static_cast<std::size_t>(s.doorway)].leaf = id;
    }
  }

 private:
  const ApartmentOptions& o_;
  Draws draws_;
  FloorPlan plan_;
  Furnishing furnishing_;
  Point3 start_ = Point3::Zero();
  int start_room_ = 0;
};

}  // namespace intervox::sim::detail
