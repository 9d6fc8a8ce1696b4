// Material names, workcell object regions, and the lab room's options (annex, window, front-only
// closet) at closed-form distances.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <string>
#include <tuple>
#include <vector>
#include <utility>

TEST_CASE("surface names round-trip and unknown names are rejected", "[sim][material]") {
  for (auto s : {intervox::sim::Surface::Diffuse, intervox::sim::Surface::Absorbing, intervox::sim::Surface::Specular,
                 intervox::sim::Surface::Transparent})
    CHECK(intervox::sim::surface_from_string(intervox::sim::to_string(s)) == s);
  CHECK_THROWS_AS(intervox::sim::surface_from_string("mirror"), intervox::InvalidArgument);
}

TEST_CASE("the workcell names the region of each object, from the table top up", "[sim][workcell]") {
  const auto w = intervox::sim::make_workcell();
  for (const char* name : {"part", "bottle", "box"}) {
    const intervox::Bounds r = w.object_region(name, 0.01);
    INFO(name);
    CHECK(r.valid());
    CHECK(r.min.z() == w.table_center.z());
    CHECK(w.objects.contains(0.5 * (r.min + r.max)));
  }
  const intervox::Bounds part = w.object_region("part", 0.0);
  CHECK(part.contains(w.table_center + intervox::Point3(0.07, 0.0, 0.01)));  // on the ring (outer radius 8 cm)
  CHECK(w.object_region("bottle", 0.0).max.z() > w.object_region("bottle", 0.0).min.z() + 0.25);  // body and neck
  CHECK_THROWS_AS(w.object_region("chair", 0.01), intervox::InvalidArgument);
  CHECK_THROWS_AS(w.object_region("part", -0.1), intervox::InvalidArgument);
}

namespace {

/// The name of the first object the ray o + t d meets and its t (none: "", -1).
std::pair<std::string, double> named_hit(const intervox::sim::Scene& s, const intervox::Point3& o,
                                         const intervox::Point3& d) {
  const auto h = s.intersect(o, d);
  return h ? std::pair<std::string, double>{s.name(h->object), h->t} : std::pair<std::string, double>{"", -1.0};
}

}  // namespace

TEST_CASE("the lab room's annex is reached through an open doorway in the east wall, at closed-form distances",
          "[sim][scenes]") {
  namespace sim = intervox::sim;
  using intervox::Point3;
  const auto plain = sim::make_lab_room();
  CHECK_FALSE(plain.annex_interior.has_value());
  CHECK_FALSE(plain.window.has_value());
  CHECK(plain.closet == plain.closet_body);
  // Without the annex the east wall stops a beam at x = 8.
  auto [name, t] = named_hit(plain.scene, {7.0, 5.3, 1.0}, {1.0, 0.0, 0.0});
  CHECK(name == "wall_east");
  CHECK(t == Approx(1.0));

  sim::LabRoomOptions o;
  o.annex = true;
  const auto lab = sim::make_lab_room(o);
  REQUIRE(lab.annex_interior.has_value());
  REQUIRE(lab.annex_doorway.has_value());
  // Through the doorway (y in [4.7, 5.9], below 2.1 m) to the annex's east wall at x = 11.1.
  std::tie(name, t) = named_hit(lab.scene, {7.0, 5.3, 1.0}, {1.0, 0.0, 0.0});
  CHECK(name == "annex_wall_east");
  CHECK(t == Approx(4.1));
  // Above the doorway: the lintel; beside it: the wall; the door leaf stays where it was.
  std::tie(name, t) = named_hit(lab.scene, {7.0, 5.3, 2.5}, {1.0, 0.0, 0.0});
  CHECK(name == "wall_east_lintel");
  CHECK(t == Approx(1.0));
  std::tie(name, t) = named_hit(lab.scene, {7.0, 4.65, 1.0}, {1.0, 0.0, 0.0});
  CHECK(name == "wall_east");
  std::tie(name, t) = named_hit(lab.scene, {7.5, 4.0, 1.0}, {1.0, 0.0, 0.0});
  CHECK(name == "door");
  CHECK(t == Approx(0.499));
  // The annex has a floor, a crate and a shelf where the options say.
  std::tie(name, t) = named_hit(lab.scene, {9.0, 5.0, 1.0}, {0.0, 0.0, -1.0});
  CHECK(name == "annex_floor");
  CHECK(t == Approx(1.0));
  std::tie(name, t) = named_hit(lab.scene, {9.0, 5.65, 0.3}, {1.0, 0.0, 0.0});
  CHECK(name == "annex_crate");
  CHECK(t == Approx(0.3));
  CHECK(lab.annex_interior->contains(Point3(9.0, 5.0, 1.0)));
  CHECK(lab.annex_doorway->contains(Point3(8.05, 5.3, 1.0)));
  CHECK_FALSE(lab.scene.inside(Point3(8.05, 5.3, 1.0)));  // the doorway is free
  CHECK(lab.scene.inside(Point3(8.05, 4.0, 1.0)));        // the wall beside it is not
}

TEST_CASE("the lab room's window lets beams out to real things beyond the south wall", "[sim][scenes]") {
  namespace sim = intervox::sim;
  sim::LabRoomOptions o;
  o.window = true;
  const auto lab = sim::make_lab_room(o);
  REQUIRE(lab.window.has_value());
  // Through the opening (x in [5.0, 6.4], z in [0.3, 1.6]): the crate 1.2 m outside at crate
  // height, the fence 3.1 m outside above it; the sill below and the lintel above the opening.
  auto [name, t] = named_hit(lab.scene, {5.7, 1.0, 0.5}, {0.0, -1.0, 0.0});
  CHECK(name == "crate_outside");
  CHECK(t == Approx(2.2));
  std::tie(name, t) = named_hit(lab.scene, {5.7, 1.0, 1.0}, {0.0, -1.0, 0.0});
  CHECK(name == "fence_outside");
  CHECK(t == Approx(4.1));
  std::tie(name, t) = named_hit(lab.scene, {5.7, 1.0, 0.2}, {0.0, -1.0, 0.0});
  CHECK(name == "wall_south_sill");
  CHECK(t == Approx(1.0));
  std::tie(name, t) = named_hit(lab.scene, {5.7, 1.0, 2.0}, {0.0, -1.0, 0.0});
  CHECK(name == "wall_south_lintel");
  std::tie(name, t) = named_hit(lab.scene, {4.5, 1.0, 1.0}, {0.0, -1.0, 0.0});
  CHECK(name == "wall_south");
  CHECK(t == Approx(1.0));
}

TEST_CASE("a front-only closet has its material on the face towards the room and the room's elsewhere",
          "[sim][scenes]") {
  namespace sim = intervox::sim;
  sim::LabRoomOptions o;
  o.closet_material = sim::Material::mirror();
  o.closet_front_only = true;
  const auto lab = sim::make_lab_room(o);
  REQUIRE(lab.closet != lab.closet_body);
  CHECK(lab.scene.material(lab.closet).surface == sim::Surface::Specular);
  CHECK(lab.scene.material(lab.closet_body).surface == sim::Surface::Diffuse);
  // Head-on from the room: the mirror front 1 mm before the body's face at x = 0.601.
  const auto front = lab.scene.intersect({2.0, 4.0, 1.0}, {-1.0, 0.0, 0.0});
  REQUIRE(front);
  CHECK(front->object == lab.closet);
  CHECK(front->t == Approx(1.398));
  // From above and from the side: the wooden body.
  const auto top = lab.scene.intersect({0.3, 4.0, 2.5}, {0.0, 0.0, -1.0});
  REQUIRE(top);
  CHECK(top->object == lab.closet_body);
  CHECK(top->t == Approx(0.5));
  const auto side = lab.scene.intersect({0.3, 3.0, 1.0}, {0.0, 1.0, 0.0});
  REQUIRE(side);
  CHECK(side->object == lab.closet_body);
  CHECK(side->t == Approx(0.4));
  // The whole closet of the material without the option.
  o.closet_front_only = false;
  const auto whole = sim::make_lab_room(o);
  CHECK(whole.scene.material(whole.closet).surface == sim::Surface::Specular);
  CHECK(whole.closet == whole.closet_body);
}

TEST_CASE("the lab room's floor plan lies on its walls and leaves its doorway and window open", "[sim][scenes]") {
  namespace sim = intervox::sim;
  using intervox::Point3;
  for (const auto& [annex, window] :
       {std::pair{false, false}, std::pair{true, false}, std::pair{false, true}, std::pair{true, true}}) {
    sim::LabRoomOptions o;
    o.annex = annex;
    o.window = window;
    const auto lab = sim::make_lab_room(o);
    const std::vector<intervox::PlanePatch> plan = sim::lab_floor_plan(lab);
    INFO("annex " << annex << ", window " << window);
    CHECK(plan.size() == 4u + (annex ? 8u : 0u) + (window ? 3u : 0u));
    // Oracle: the scene. Every point of a patch (a 9 x 9 lattice, corners pulled in by 1 cm), 5 cm
    // behind it on the side away from the free inside, lies inside a wall; 5 cm before it is free.
    const intervox::Bounds inside_annex = lab.annex_interior.value_or(lab.interior);
    const auto free_inside = [&](const Point3& p) { return lab.interior.contains(p) || inside_annex.contains(p); };
    for (const intervox::PlanePatch& w : plan) {
      w.validate();
      for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 8; ++j) {
          const Point3 p = w.center + w.axis_u * ((w.half_u - 0.01) * (i / 4.0 - 1.0)) +
                           w.axis_v() * ((w.half_v - 0.01) * (j / 4.0 - 1.0));
          const Point3 in =
              free_inside(p + 0.05 * w.normal) ? Point3(p + 0.05 * w.normal) : Point3(p - 0.05 * w.normal);
          const Point3 out = 2.0 * p - in;
          INFO("patch at " << w.center.transpose() << ", point " << p.transpose());
          CHECK(free_inside(in));
          CHECK(lab.scene.inside(out));
        }
    }
    // The openings' centres lie on no patch.
    for (const auto& opening : {lab.annex_doorway, lab.window})
      if (opening) {
        const Point3 c = 0.5 * (opening->min + opening->max);
        for (const intervox::PlanePatch& w : plan) CHECK_FALSE(w.contains(c, 0.06));
      }
  }
  // The closet's surfaces: its five faces off the wall and on the wall, or the front alone.
  sim::LabRoomOptions o;
  const auto whole = sim::make_lab_room(o);
  const auto faces = sim::lab_closet_surfaces(whole);
  CHECK(faces.size() == 5u);
  const intervox::Bounds b = whole.scene.object_bounds(whole.closet);
  // Each face: on the box's boundary along its normal, holding the face's four corners.
  const std::vector<std::pair<int, double>> expected{
      {0, b.max.x()}, {0, b.min.x()}, {1, b.min.y()}, {1, b.max.y()}, {2, b.max.z()}};
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto [axis, value] = expected[f];
    CHECK(faces[f].normal == Point3::Unit(axis));
    CHECK(faces[f].center[axis] == value);
    const int a = (axis + 1) % 3, c = (axis + 2) % 3;
    for (const double u : {b.min[a], b.max[a]})
      for (const double v : {b.min[c], b.max[c]}) {
        Point3 corner;
        corner[axis] = value;
        corner[a] =
            u == b.min[a] ? u + 1e-9 : u - 1e-9;  // a hair inside: the rectangle's edges are exact only up to rounding
        corner[c] = v == b.min[c] ? v + 1e-9 : v - 1e-9;
        CHECK(faces[f].contains(corner, 1e-9));
      }
  }
  o.closet_front_only = true;
  const auto front = sim::lab_closet_surfaces(sim::make_lab_room(o));
  REQUIRE(front.size() == 1u);
  CHECK(front.front().center.x() == Approx(0.602));
  CHECK(front.front().half_u == Approx(0.6));
  CHECK(front.front().half_v == Approx(1.0));
}
