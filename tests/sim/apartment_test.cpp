// The random apartments (sim/apartment.hpp) and the oracle's sensor (sim/oracle.hpp): invariants
// over many seeds against independent oracles (the planners' own exploration map of the true
// scene for reachability, the scene's materials for the lying surfaces, ray casts for the twin's
// geometry), the options' errors, and the oracle's beams at hand-made surfaces.
#include <catch2/catch.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/sim/apartment.hpp>
#include <intervox/sim/oracle.hpp>
#include <intervox/sim/sim.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace {

namespace iv = intervox;
namespace sim = intervox::sim;

/// Every object of \p s whose material is not diffuse, in id order.
std::vector<sim::ObjectId> non_diffuse_objects(const sim::Scene& s) {
  std::vector<sim::ObjectId> out;
  for (sim::ObjectId i = 0; i < s.size(); ++i)
    if (s.material(i).surface != sim::Surface::Diffuse) out.push_back(i);
  return out;
}

/// The reachable floor (m²) of the truth's exploration map inside each room, from the start.
std::vector<double> reachable_area_per_room(const sim::Apartment& a, const iv::GridGeometry& g, const iv::TruthMap& t) {
  std::vector<double> area(a.rooms.size(), 0.0);
  for (int y = 0; y < t.map.height(); ++y)
    for (int x = 0; x < t.map.width(); ++x) {
      if (!t.map.reachable({x, y})) continue;
      const iv::Point3 c = g.center(iv::Key{t.origin.x + x, t.origin.y + y, 0});
      for (std::size_t r = 0; r < a.rooms.size(); ++r)
        if (c.x() > a.rooms[r].min.x() && c.x() < a.rooms[r].max.x() && c.y() > a.rooms[r].min.y() &&
            c.y() < a.rooms[r].max.y())
          area[r] += g.resolution() * g.resolution();
    }
  return area;
}

/// True if the truth's map reaches the cell under \p p.
bool reaches(const iv::GridGeometry& g, const iv::TruthMap& t, const iv::Point3& p) {
  const iv::Key k = g.key(p);
  return t.map.reachable({k.x - t.origin.x, k.y - t.origin.y});
}

}  // namespace

TEST_CASE("a thousand consecutive seeds give valid apartments whose every room the robot reaches from the start, "
          "with every fixture kind in at least a tenth of them",
          "[sim][apartment][slow]") {
  const iv::GridGeometry g(0.05);
  iv::ExplorationMapParams map;  // the planners' robot: radius 0.35 m
  std::array<int, sim::kFixtureKinds> present{};
  std::array<int, 5> rooms{};
  for (std::uint64_t seed = 1; seed <= 1000; ++seed) {
    INFO("seed " << seed);
    const sim::Apartment a = sim::make_apartment(seed);
    REQUIRE(a.rooms.size() >= 1);
    REQUIRE(a.rooms.size() <= 4);
    ++rooms[a.rooms.size()];
    CHECK((a.footprint.max.x() - a.footprint.min.x()) * (a.footprint.max.y() - a.footprint.min.y()) <=
          a.options.max_area + 1e-9);
    // The start: inside its room, clear of every object by the start clearance.
    CHECK(a.rooms[static_cast<std::size_t>(a.start_room)].contains(a.start));
    const double c = (a.options.start_clearance - 0.05) / std::sqrt(2.0);  // the square inside the clearance disk
    CHECK_FALSE(a.scene.overlaps({a.start + iv::Point3(-c, -c, 0.01), a.start + iv::Point3(c, c, 2.0)}));
    // Every room reachable from the start on the planners' own map of the true scene, and every
    // doorway that joins the rooms passable (its centre reached).
    const iv::TruthMap truth = iv::truth_exploration_map(a.scene, g, a.band(), map, a.start);
    for (const double area : reachable_area_per_room(a, g, truth)) CHECK(area >= 0.5);
    for (const sim::ApartmentDoorway& d : a.doorways) {
      if (!d.tree) continue;
      CHECK(d.state == sim::DoorwayState::Open);
      CHECK(reaches(g, truth, 0.5 * (d.opening.min + d.opening.max)));
    }
    // The truth's lying surfaces are exactly the objects whose material lies.
    CHECK(a.lying_objects() == non_diffuse_objects(a.scene));
    for (std::size_t k = 0; k < sim::kFixtureKinds; ++k) present[k] += a.has(static_cast<sim::FixtureKind>(k));
  }
  for (std::size_t k = 0; k < sim::kFixtureKinds; ++k) {
    INFO(sim::to_string(static_cast<sim::FixtureKind>(k)) << " in " << present[k] << " of 1000 worlds");
    CHECK(present[k] >= 100);
  }
  for (int n = 1; n <= 4; ++n) CHECK(rooms[static_cast<std::size_t>(n)] >= 150);  // every room count drawn
}

TEST_CASE("an apartment is the same for the same seed and options, and differs between seeds", "[sim][apartment]") {
  const sim::Apartment a = sim::make_apartment(42), b = sim::make_apartment(42), c = sim::make_apartment(43);
  REQUIRE(a.scene.size() == b.scene.size());
  for (sim::ObjectId i = 0; i < a.scene.size(); ++i) {
    CHECK(a.scene.name(i) == b.scene.name(i));
    CHECK(a.scene.object_bounds(i).min == b.scene.object_bounds(i).min);
    CHECK(a.scene.object_bounds(i).max == b.scene.object_bounds(i).max);
  }
  CHECK(a.start == b.start);
  const bool same = a.scene.size() == c.scene.size() && a.start == c.start && a.footprint.max == c.footprint.max;
  CHECK_FALSE(same);
}

TEST_CASE("the honest twin has the same geometry with every surface diffuse", "[sim][apartment]") {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    INFO("seed " << seed);
    const sim::Apartment a = sim::make_apartment(seed);
    const sim::Scene twin = a.honest_twin();
    REQUIRE(twin.size() == a.scene.size());
    CHECK(non_diffuse_objects(twin).empty());
    for (sim::ObjectId i = 0; i < twin.size(); ++i) {
      CHECK(twin.shape(i) == a.scene.shape(i));
      CHECK(twin.object_bounds(i).min == a.scene.object_bounds(i).min);
      CHECK(twin.object_bounds(i).max == a.scene.object_bounds(i).max);
    }
    // Rays from the start meet the same object at the same range in both.
    for (int k = 0; k < 64; ++k) {
      const double yaw = 2.0 * 3.141592653589793 * k / 64.0;
      const iv::Point3 o = a.start + iv::Point3(0.0, 0.0, 0.5),
                       d(std::cos(yaw), std::sin(yaw), 0.1 * std::sin(3.0 * yaw));
      const auto h1 = a.scene.intersect(o, d), h2 = twin.intersect(o, d);
      REQUIRE(h1.has_value() == h2.has_value());
      if (h1) {
        CHECK(h1->object == h2->object);
        CHECK(h1->t == h2->t);
      }
    }
  }
}

TEST_CASE("apartment fixtures name their lying object, their room and, for planar ones, their plane",
          "[sim][apartment]") {
  int seen = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const sim::Apartment a = sim::make_apartment(seed);
    for (const sim::ApartmentFixture& f : a.fixtures) {
      INFO("seed " << seed << ": " << sim::to_string(f.kind) << " " << a.scene.name(f.surface));
      ++seen;
      CHECK(a.scene.material(f.surface).surface != sim::Surface::Diffuse);
      CHECK(f.room >= 0);
      CHECK(f.room < static_cast<int>(a.rooms.size()));
      const sim::Surface s = a.scene.material(f.surface).surface;
      switch (f.kind) {
        case sim::FixtureKind::GlassPartition:
        case sim::FixtureKind::GlassDoor:
        case sim::FixtureKind::GlassWindow:
          CHECK(s == sim::Surface::Transparent);
          break;
        case sim::FixtureKind::BlackFurniture:
          CHECK(s == sim::Surface::Absorbing);
          break;
        default:
          CHECK(s == sim::Surface::Specular);
      }
      if (f.kind == sim::FixtureKind::MirrorWardrobe || f.kind == sim::FixtureKind::MirrorCabinet) {
        REQUIRE(f.body.has_value());
        // The mirror stands in front of its body: the front is the face towards the room, not the wall.
        const iv::Bounds body = a.scene.object_bounds(*f.body);
        REQUIRE(f.plane.has_value());
        const double depth = f.kind == sim::FixtureKind::MirrorWardrobe ? 0.6 : 0.45;
        CHECK(std::abs((body.max - body.min).dot(f.plane->normal.cwiseAbs()) - depth) < 0.01);
      }
      if (f.plane) {
        // The plane passes through the surface object's bounds' centre (every planar fixture is flat).
        const iv::Point3 centre = 0.5 * (f.bounds.min + f.bounds.max);
        CHECK(std::abs(f.plane->normal.dot(centre - f.plane->center)) < 0.03);
      }
    }
  }
  CHECK(seen > 40);
}

TEST_CASE("real space is inside a room and inside no solid: the phantom behind a wall mirror is not real",
          "[sim][apartment]") {
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const sim::Apartment a = sim::make_apartment(seed);
    CHECK(a.real_space(a.start + iv::Point3(0.0, 0.0, 0.5)));
    CHECK_FALSE(a.real_space(iv::Point3(-1.0, -1.0, 0.5)));  // outside the outer walls
    for (const sim::ApartmentFixture& f : a.fixtures) {
      if (f.kind != sim::FixtureKind::WallMirror || !f.plane) continue;
      // A point 1 m in front of the mirror and its reflection 1 m behind it.
      const iv::Point3 front = f.plane->center + 1.0 * f.plane->normal,
                       behind = f.plane->center - 1.0 * f.plane->normal;
      INFO("seed " << seed);
      CHECK_FALSE(a.real_space(behind));
      if (a.scene.overlaps({front - iv::Point3::Constant(0.05), front + iv::Point3::Constant(0.05)})) continue;
      CHECK(std::ranges::any_of(a.rooms, [&](const iv::Bounds& r) { return r.contains(front); }));
      return;  // one mirror checked both ways is enough
    }
  }
  FAIL("no seed in 1..200 has a wall mirror with free space before it");
}

TEST_CASE("apartment options outside their ranges are refused with the option's name", "[sim][apartment]") {
  sim::ApartmentOptions o;
  o.max_rooms = 5;
  CHECK_THROWS_WITH(sim::make_apartment(1, o), Catch::Contains("max_rooms"));
  o = {};
  o.door_width_min = 0.5;
  CHECK_THROWS_WITH(sim::make_apartment(1, o), Catch::Contains("door_width_min"));
  o = {};
  o.mix[3] = 1.5;
  CHECK_THROWS_WITH(sim::make_apartment(1, o), Catch::Contains("mix"));
  o = {};
  o.start_clearance = 0.1;
  CHECK_THROWS_WITH(sim::make_apartment(1, o), Catch::Contains("start_clearance"));
}

TEST_CASE("a mix of zero gives apartments without lying surfaces, a mix of one holds most kinds", "[sim][apartment]") {
  sim::ApartmentOptions none;
  none.mix.fill(0.0);
  sim::ApartmentOptions all;
  all.mix.fill(1.0);
  all.min_rooms = 3;
  int kinds = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    CHECK(sim::make_apartment(seed, none).fixtures.empty());
    const sim::Apartment a = sim::make_apartment(seed, all);
    for (std::size_t k = 0; k < sim::kFixtureKinds; ++k) kinds += a.has(static_cast<sim::FixtureKind>(k));
  }
  CHECK(kinds >= 70);  // of 100: a kind is left out only where there is no room for it
}

TEST_CASE("the oracle ends beams at the surfaces it is told lie and leaves the others", "[sim][apartment][oracle]") {
  sim::Scene s;
  const sim::ObjectId wall = s.add_box({{5.0, -5.0, 0.0}, {5.1, 5.0, 3.0}}, sim::Material::diffuse(), "wall");
  const sim::ObjectId mirror =
      s.add_quad({2.0, 1.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 2.0}, sim::Material::mirror(), "mirror");
  const sim::ObjectId black = s.add_box({{3.0, -2.0, 0.0}, {3.5, -1.0, 1.0}}, sim::Material::absorbing(), "black");
  (void)wall;
  const std::vector<char> lying = [&] {
    std::vector<char> l(s.size(), 0);
    l[mirror] = l[black] = 1;
    return l;
  }();
  const iv::Point3 o(0.0, 1.5, 0.5);
  std::vector<iv::Beam> beams{
      {o, o + iv::Point3(9.0, 0.0, 0.0), true},    // through the mirror's line: a phantom 9 m away
      {o, o + iv::Point3(4.99, -1.4, 0.0), true},  // passes below the mirror's edge: a direct return at the wall
      {o, o + 10.0 * iv::Point3(3.25, -3.0, 0.0).normalized(), false},  // no return, towards the black box
  };
  const std::vector<iv::Beam> before = beams;
  CHECK(sim::end_at_lying_surfaces(s, lying, beams) == 2);
  CHECK(beams[0].hit);
  CHECK(beams[0].end.isApprox(iv::Point3(2.0, 1.5, 0.5)));
  CHECK(beams[1].end == before[1].end);  // its line meets the diffuse wall first
  CHECK(beams[2].hit);
  CHECK(std::abs(beams[2].end.x() - 3.0) < 1e-9);
  // Told nothing, it changes nothing.
  std::vector<iv::Beam> again = before;
  CHECK(sim::end_at_lying_surfaces(s, std::vector<char>(s.size(), 0), again) == 0);
}

TEST_CASE("the oracle rig knows exactly the apartment's lying surfaces and sees no phantom",
          "[sim][apartment][oracle]") {
  sim::ApartmentOptions o;
  o.mix.fill(0.0);
  o.mix[static_cast<std::size_t>(sim::FixtureKind::WallMirror)] = 1.0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const sim::Apartment a = sim::make_apartment(seed, o);
    if (!a.has(sim::FixtureKind::WallMirror)) continue;
    const iv::SensorRig rig = iv::SensorRig::mobile_base();
    sim::OracleRig oracle = sim::make_oracle_rig(a, rig, seed);
    CHECK(oracle.lying_objects() == a.lying_objects());
    // Scans from the start and from in front of the mirror: every return lies on the first
    // surface of its line (within 5 sigma of the 1 cm noise), so none is a phantom.
    const sim::ApartmentFixture& m = a.fixtures.front();
    const iv::Point3 before_mirror = m.plane->center + 1.2 * m.plane->normal;
    std::size_t returns = 0;
    for (const iv::Point3& at : {a.start, iv::Point3(before_mirror.x(), before_mirror.y(), 0.0)}) {
      if (a.scene.overlaps({at + iv::Point3(-0.3, -0.3, 0.05), at + iv::Point3(0.3, 0.3, 1.0)})) continue;
      std::size_t phantom = 0;
      for (const iv::Beam& b : oracle(iv::planar_pose(at, 0.0))) {
        if (!b.hit) continue;
        ++returns;
        const iv::Point3 d = b.end - b.origin;
        const auto first = a.scene.intersect(b.origin, d.normalized());
        phantom += !first || std::abs(first->t - d.norm()) > 0.05 ? 1 : 0;
      }
      CHECK(phantom == 0);
    }
    CHECK(returns > 1000);
    CHECK(oracle.corrected() > 0);
    return;
  }
  FAIL("no seed in 1..6 has a wall mirror");
}
