// The two mirror-symmetric rooms joined by a doorway (make_symmetric_rooms, issue 32): the rooms
// are mirror images about the shared wall's mid-plane, the doorway is open, and with the mirror
// panel a beam folded by the mirror ends exactly on a real surface of the other room, at the
// mirror image of the surface it truly met.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace {
namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

/// The image of the direction \p d under the rooms' reflection x -> 2 symmetry_x - x.
Point3 symrooms_mirror_dir(const Point3& d) { return {-d.x(), d.y(), d.z()}; }

/// The name of the image of an object: west_* <-> east_*; every other object is its own image.
std::string symrooms_image_name(const std::string& name) {
  if (name.rfind("west_", 0) == 0) return "east_" + name.substr(5);
  if (name.rfind("east_", 0) == 0) return "west_" + name.substr(5);
  return name;
}

/// Deterministic directions spread over the sphere (a Fibonacci lattice).
std::vector<Point3> symrooms_directions(int n) {
  std::vector<Point3> out;
  const double golden = 2.39996322972865332;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
    out.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return out;
}
}  // namespace

TEST_CASE("the two rooms are mirror images about the shared wall's mid-plane", "[sim][scenes][symmetric]") {
  const sim::SymmetricRooms r = sim::make_symmetric_rooms();
  CHECK_FALSE(r.mirror.has_value());
  CHECK_FALSE(r.niche.has_value());
  CHECK_FALSE(r.mirror_object.has_value());
  CHECK(r.symmetry_x == 4.1);
  CHECK(r.reflect(Point3(1.0, 2.0, 3.0)).isApprox(Point3(7.2, 2.0, 3.0), 1e-15));
  // Every object has its image: west_* <-> east_* with reflected bounds, the rest symmetric itself.
  int pairs = 0;
  for (sim::ObjectId id = 0; id < r.scene.size(); ++id) {
    const std::string name = r.scene.name(id);
    INFO(name);
    const auto image = r.scene.find(symrooms_image_name(name));
    REQUIRE(image.has_value());
    pairs += *image != id;
    const iv::Bounds& b = r.scene.object_bounds(id);
    const iv::Bounds& m = r.scene.object_bounds(*image);
    CHECK(std::abs(m.min.x() - (2 * r.symmetry_x - b.max.x())) < 1e-12);
    CHECK(std::abs(m.max.x() - (2 * r.symmetry_x - b.min.x())) < 1e-12);
    CHECK((m.min.tail<2>() - b.min.tail<2>()).norm() < 1e-12);
    CHECK((m.max.tail<2>() - b.max.tail<2>()).norm() < 1e-12);
    CHECK(r.scene.shape(id) == r.scene.shape(*image));
  }
  CHECK(pairs == 2 * 10);  // the outer wall, shelf, table top, four legs, crate, cabinet and bin of each room
  // Rays from points of the west room and their images meet the same surfaces at the same range.
  const std::vector<Point3> origins = {
      {1.0, 1.0, 0.5}, {2.0, 1.5, 1.2}, {3.5, 1.1, 1.0}, {3.8, 2.7, 0.3}, {0.7, 3.8, 2.2}};
  int hits = 0;
  for (const Point3& o : origins)
    for (const Point3& d : symrooms_directions(400)) {
      const auto a = r.scene.intersect(o, d);
      const auto b = r.scene.intersect(r.reflect(o), symrooms_mirror_dir(d));
      REQUIRE(a.has_value());  // the rooms are closed
      REQUIRE(b.has_value());
      CHECK(std::abs(a->t - b->t) < 1e-9);
      CHECK(r.scene.name(b->object) == symrooms_image_name(r.scene.name(a->object)));
      ++hits;
    }
  CHECK(hits == 5 * 400);
  // The free insides and the base's start hold nothing.
  for (const iv::Bounds& room : r.rooms) {
    CHECK_FALSE(r.scene.inside(0.5 * (room.min + room.max)));
    CHECK(room.max.z() == 2.6);
  }
  CHECK(r.rooms[1].min.x() == 4.2);
  CHECK(r.scene.inside(Point3(4.1, 2.7, 1.0)));  // the shared wall beside the doorway, no mirror
  const iv::Bounds base{r.start + Point3(-0.37, -0.37, 0.01), r.start + Point3(0.37, 0.37, 1.0)};
  CHECK_FALSE(r.scene.overlaps(base));
}

TEST_CASE("the doorway between the symmetric rooms is open, at closed-form distances", "[sim][scenes][symmetric]") {
  for (const bool mirror : {false, true}) {
    sim::SymmetricRoomsOptions o;
    o.mirror = mirror;
    const sim::SymmetricRooms r = sim::make_symmetric_rooms(o);
    INFO("mirror " << mirror);
    // The opening holds nothing (shrunk by 1 mm from the wall's sides, the lintel and the floor).
    const iv::Bounds gap{r.doorway.min + Point3(0.0, 0.001, 0.001), r.doorway.max - Point3(0.0, 0.001, 0.001)};
    CHECK_FALSE(r.scene.overlaps(gap));
    // Through the doorway a beam crosses into the east room and meets its east wall at x = 8.2.
    const auto through = r.scene.intersect({3.5, 1.1, 1.0}, Point3::UnitX());
    REQUIRE(through.has_value());
    CHECK(r.scene.name(through->object) == "east_wall");
    CHECK(through->t == Approx(4.7).epsilon(1e-12));
    // Above it the lintel, beside it the wall, at x = 4.0.
    const auto lintel = r.scene.intersect({3.5, 1.1, 2.3}, Point3::UnitX());
    REQUIRE(lintel.has_value());
    CHECK(r.scene.name(lintel->object) == "doorway_lintel");
    CHECK(lintel->t == Approx(0.5).epsilon(1e-12));
    const auto wall = r.scene.intersect({3.5, 0.3, 1.0}, Point3::UnitX());
    REQUIRE(wall.has_value());
    CHECK(r.scene.name(wall->object) == "shared_wall_south");
    // Beside the doorway: the mirror in the mid-plane x = 4.1, else the plain wall at x = 4.0.
    const auto panel = r.scene.intersect({3.0, 2.7, 1.0}, Point3::UnitX());
    REQUIRE(panel.has_value());
    CHECK(r.scene.name(panel->object) == (mirror ? "mirror" : "shared_wall_panel"));
    CHECK(panel->t == Approx(mirror ? 1.1 : 1.0).epsilon(1e-12));
    if (mirror) {
      REQUIRE(r.mirror.has_value());
      REQUIRE(r.niche.has_value());
      REQUIRE(r.mirror_object.has_value());
      CHECK(r.scene.material(*r.mirror_object).surface == sim::Surface::Specular);
      CHECK(r.mirror->min.x() == r.symmetry_x);
      CHECK(r.mirror->max.x() == r.symmetry_x);
      CHECK(r.mirror->min.y() == 2.2);
      CHECK(r.mirror->max.y() == 3.2);
      CHECK(r.mirror->max.z() == 2.1);
      CHECK_FALSE(
          r.scene.overlaps({r.niche->min + Point3(0.001, 0.001, 0.001), r.niche->max - Point3(0.001, 0.001, 0.001)}));
    }
  }
  sim::SymmetricRoomsOptions bad;
  bad.default_material.sigma = -1.0;
  CHECK_THROWS_AS(sim::make_symmetric_rooms(bad), iv::InvalidArgument);
  bad = {};
  bad.mirror_material.p_direct = 2.0;
  CHECK_THROWS_AS(sim::make_symmetric_rooms(bad), iv::InvalidArgument);
}

TEST_CASE("the mirror between the symmetric rooms shows the real east room: phantoms land on its surfaces",
          "[sim][scenes][symmetric][reflection]") {
  sim::SymmetricRoomsOptions o;
  o.mirror = true;
  o.default_material = sim::Material::diffuse(0.0);  // noise-free, so that ranges are exact
  const sim::SymmetricRooms r = sim::make_symmetric_rooms(o);
  // Beams from three points of the west room towards points spread over the mirror.
  int folded = 0, on_real = 0;
  for (const Point3& origin : {Point3(2.5, 2.7, 1.0), Point3(1.2, 1.4, 0.5), Point3(3.2, 3.6, 1.8)})
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j) {
        const Point3 target(r.symmetry_x, 2.25 + 0.1125 * i, 0.05 + 0.25 * j);
        const Point3 dir = (target - origin).normalized();
        sim::BeamRng rng(1, 0, static_cast<std::uint64_t>(i * 9 + j));
        const sim::TraceResult t = sim::trace(r.scene, origin, dir, 0.1, 30.0, rng);
        INFO("origin " << origin.transpose() << " target " << target.transpose());
        if (r.scene.intersect(origin, dir)->object != *r.mirror_object) continue;  // the table hides the mirror
        REQUIRE(t.path == sim::BeamPath::Reflected);
        CHECK(t.bounces == 1);
        ++folded;
        // The phantom is the mirror image of the surface the beam truly met, in the east room ...
        const Point3 phantom = origin + t.range * dir;
        CHECK((phantom - r.reflect(t.surface)).norm() < 1e-9);
        CHECK(t.surface.x() < r.symmetry_x);
        CHECK(phantom.x() > r.symmetry_x);
        // ... and, where the phantom's last 5 cm lie in the east room (not in the wall behind the
        // niche, whose west half alone is cut away), on a real surface there: a beam along the
        // same direction from 5 cm before it meets the scene exactly there (the image of the
        // folded path's last 5 cm, which were free).
        const Point3 before = phantom - 0.05 * dir;
        if (before.x() <= r.rooms[1].min.x()) continue;
        const iv::Bounds east{r.rooms[1].min.array() - 1e-9, r.rooms[1].max.array() + 1e-9};  // rounding
        CHECK(east.contains(phantom));
        const auto real = r.scene.intersect(before, dir);
        REQUIRE(real.has_value());
        CHECK(std::abs(real->t - 0.05) < 1e-9);
        ++on_real;
      }
  CHECK(folded > 150);
  CHECK(on_real > 100);
}

TEST_CASE("a scan of the symmetric rooms is the same for one and two threads", "[sim][scenes][symmetric][threaded]") {
  sim::SymmetricRoomsOptions o;
  o.mirror = true;
  const sim::SymmetricRooms r = sim::make_symmetric_rooms(o);
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  iv::Pose body = iv::Pose::Identity();
  body.translation() = Point3(3.0, 2.0, 0.0);
  sim::SimOptions one, two;
  two.threads = 2;
  std::vector<sim::BeamPath> p1, p2;
  const auto a = sim::simulate(rig, r.scene, body, 5, one, &p1);
  const auto b = sim::simulate(rig, r.scene, body, 5, two, &p2);
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) REQUIRE(a[i].end == b[i].end);
  CHECK(p1 == p2);
  CHECK(std::count(p1.begin(), p1.end(), sim::BeamPath::Reflected) > 0);
}
