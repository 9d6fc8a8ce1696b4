// Ray intersection and inside tests against closed forms, and the BVH against brute force.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <cmath>
#include <numbers>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

namespace {
double first_hit(const sim::Scene& s, Point3 o, Point3 d) {
  const auto h = s.intersect(o, d.normalized());
  return h ? h->t : -1.0;
}
}  // namespace

TEST_CASE("a ray meets an axis-aligned box at the slab distance, also from inside", "[sim][intersect]") {
  sim::Scene s;
  s.add_box({{1, -1, -1}, {2, 1, 1}});
  CHECK(first_hit(s, {0, 0, 0}, {1, 0, 0}) == Approx(1.0));
  // 45° in the xy plane: enters x = 1 at y = 1 (the edge), t = sqrt 2.
  CHECK(first_hit(s, {0, 0, 0}, {1, 1, 0}) == Approx(std::sqrt(2.0)));
  CHECK(first_hit(s, {1.5, 0, 0}, {1, 0, 0}) == Approx(0.5));  // inside: the exit face
  CHECK(first_hit(s, {0, 0, 0}, {-1, 0, 0}) == -1.0);
  CHECK(first_hit(s, {0, 2, 0}, {1, 0, 0}) == -1.0);
}

TEST_CASE("a ray meets a sphere at d - r and from inside at the far root", "[sim][intersect]") {
  sim::Scene s;
  s.add_sphere({3, 0, 0}, 0.5);
  CHECK(first_hit(s, {0, 0, 0}, {1, 0, 0}) == Approx(2.5));
  CHECK(first_hit(s, {3, 0, 0}, {0, 0, 1}) == Approx(0.5));
  // Off-centre by 0.3: chord half-length 0.4, so t = 3 - 0.4.
  CHECK(first_hit(s, {0, 0.3, 0}, {1, 0, 0}) == Approx(2.6));
  CHECK(first_hit(s, {0, 0.6, 0}, {1, 0, 0}) == -1.0);
}

TEST_CASE("a ray meets a cylinder on its side and on its caps", "[sim][intersect]") {
  sim::Scene s;
  s.add_cylinder({0, 0, 0}, {0, 0, 2}, 0.5);
  CHECK(first_hit(s, {3, 0, 1}, {-1, 0, 0}) == Approx(2.5));    // side
  CHECK(first_hit(s, {0.2, 0, 5}, {0, 0, -1}) == Approx(3.0));  // top cap
  CHECK(first_hit(s, {0.2, 0, -1}, {0, 0, 1}) == Approx(1.0));  // bottom cap
  CHECK(first_hit(s, {3, 0, 2.5}, {-1, 0, 0}) == -1.0);         // above
  // Slanted into the top rim: from (3, 0, 3) towards (0, 0, 0): meets z = 2 at x = 2 (outside
  // radius), then the side x = 0.5 at z = 0.5: t = |(2.5, 0, 2.5)|.
  CHECK(first_hit(s, {3, 0, 3}, {-1, 0, -1}) == Approx(2.5 * std::sqrt(2.0)));
  // A tilted cylinder along x.
  sim::Scene t;
  t.add_cylinder({0, 0, 0}, {4, 0, 0}, 1.0);
  CHECK(first_hit(t, {2, 0, 5}, {0, 0, -1}) == Approx(4.0));
  CHECK(first_hit(t, {-3, 0, 0}, {1, 0, 0}) == Approx(3.0));
}

TEST_CASE("a ray meets a quad inside its edges only, from both sides", "[sim][intersect]") {
  sim::Scene s;
  s.add_quad({2, -1, -1}, {0, 2, 0}, {0, 0, 2});  // x = 2, |y|, |z| <= 1
  CHECK(first_hit(s, {0, 0, 0}, {1, 0, 0}) == Approx(2.0));
  CHECK(first_hit(s, {4, 0.5, 0.5}, {-1, 0, 0}) == Approx(2.0));
  CHECK(first_hit(s, {0, 0, 0}, {2, 0.9, 0}) == Approx(std::hypot(2.0, 0.9)));
  CHECK(first_hit(s, {0, 0, 0}, {2, 1.1, 0}) == -1.0);
  CHECK(first_hit(s, {0, 0, 0}, {0, 1, 0}) == -1.0);  // parallel
}

TEST_CASE("a ray meets an oriented box at its rotated face", "[sim][intersect]") {
  sim::Scene s;
  iv::Pose p = iv::Pose::Identity();
  p.linear() = Eigen::AngleAxisd(std::numbers::pi / 4, Point3::UnitZ()).toRotationMatrix();
  p.translation() = Point3(5, 0, 0);
  s.add_oriented_box(p, {1, 1, 1});  // a diamond in xy: its near corner at x = 5 - sqrt 2
  CHECK(first_hit(s, {0, 0, 0}, {1, 0, 0}) == Approx(5 - std::sqrt(2.0)));
  CHECK(first_hit(s, {5, 5, 0}, {0, -1, 0}) == Approx(5 - std::sqrt(2.0)));
  CHECK(first_hit(s, {5 - 1.5, 0, 0}, {0, 1, 0}) == -1.0);
}

TEST_CASE("a ray meets a mesh triangle and a closed ring's wall, not its hole", "[sim][intersect]") {
  sim::Scene s;
  sim::TriangleMesh tri;
  tri.vertices = {{1, -1, -1}, {1, 1, -1}, {1, 0, 1}};
  tri.triangles = {{0, 1, 2}};
  const auto id = s.add_mesh(tri);
  CHECK_FALSE(s.solid(id));
  CHECK(first_hit(s, {0, 0, 0}, {1, 0, 0}) == Approx(1.0));
  CHECK(first_hit(s, {0, 0.9, 0.9}, {1, 0, 0}) == -1.0);

  sim::Scene r;
  const auto ring = r.add_mesh(sim::make_ring({0, 0, 0}, 0.5, 1.0, 0.2, 256));
  CHECK(r.solid(ring));
  // Straight down through the hole: nothing; through the wall: the top face at z = 0.2.
  CHECK(first_hit(r, {0, 0, 1}, {0, 0, -1}) == -1.0);
  CHECK(first_hit(r, {0.75, 0, 1}, {0, 0, -1}) == Approx(0.8));
  // Horizontally at mid height: the outer wall at ~1.0 (a 256-gon: within 1e-4).
  CHECK(first_hit(r, {3, 0.001, 0.1}, {-1, 0, 0}) == Approx(2.0).margin(1e-4));
  CHECK(r.inside({0.75, 0.0, 0.1}));
  CHECK_FALSE(r.inside({0.0, 0.0, 0.1}));
  CHECK_FALSE(r.inside({0.75, 0.0, 0.3}));
}

TEST_CASE("the BVH finds the same first hit as testing every primitive", "[sim][intersect][oracle]") {
  const auto lab = sim::make_lab_room();
  const auto cell = sim::make_workcell();
  for (const sim::Scene* scene : {&lab.scene, &cell.scene}) {
    const bool closed_room = scene == &lab.scene;
    const iv::Bounds b = scene->bounds();
    sim::BeamRng rng(7, 0, 0);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
      const Point3 o(rng.uniform(b.min.x(), b.max.x()), rng.uniform(b.min.y(), b.max.y()),
                     rng.uniform(b.min.z(), b.max.z()));
      const Point3 d = Point3(rng.normal(), rng.normal(), rng.normal()).normalized();
      const auto a = scene->intersect(o, d);
      const auto e = scene->intersect_brute_force(o, d);
      REQUIRE(a.has_value() == e.has_value());
      if (a) {
        ++hits;
        REQUIRE(a->t == Approx(e->t).margin(1e-12));
      }
    }
    // In the closed room every ray meets something; the workcell is open above and at the sides.
    if (closed_room)
      CHECK(hits == 4000);
    else
      CHECK(hits > 1000);
  }
}

TEST_CASE("ground truth marks exactly the voxels a box shares volume with", "[sim][ground_truth]") {
  sim::Scene s;
  s.add_box({{0.0, 0.0, 0.0}, {0.3, 0.2, 0.1}});
  const iv::GridGeometry g(0.1);
  const auto keys = s.ground_truth(g, {{-1, -1, -1}, {1, 1, 1}});
  CHECK(keys.size() == 3 * 2 * 1);
  CHECK(s.occupied(g, {2, 1, 0}));
  CHECK_FALSE(s.occupied(g, {3, 1, 0}));   // touches the face x = 0.3 only
  CHECK_FALSE(s.occupied(g, {0, 0, -1}));  // below the face z = 0
}

TEST_CASE("ground truth of a sphere matches the closed-form voxel/sphere overlap", "[sim][ground_truth][oracle]") {
  sim::Scene s;
  const Point3 c(0.013, -0.021, 0.034);
  const double r = 0.31;
  s.add_sphere(c, r);
  const iv::GridGeometry g(0.05);
  const iv::Bounds region{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  const auto keys = s.ground_truth(g, region);
  // Reference: every voxel of the region whose closest point to the centre lies within r.
  std::size_t expected = 0;
  const iv::KeyBox kb = g.key_box(region);
  iv::Key k;
  for (k.x = kb.min.x; k.x <= kb.max.x; ++k.x)
    for (k.y = kb.min.y; k.y <= kb.max.y; ++k.y)
      for (k.z = kb.min.z; k.z <= kb.max.z; ++k.z) {
        const Point3 lo = g.corner(k), hi = lo + Point3::Constant(0.05);
        const Point3 q = c.cwiseMax(lo).cwiseMin(hi);
        const bool occ = (q - c).norm() < r;
        expected += occ;
        REQUIRE(std::binary_search(keys.begin(), keys.end(), k) == occ);
        REQUIRE(s.occupied(g, k) == occ);
      }
  // Volume sanity: between the inscribed and circumscribed voxel counts.
  CHECK(expected == keys.size());
  CHECK(double(keys.size()) * 0.05 * 0.05 * 0.05 > 4.0 / 3.0 * std::numbers::pi * r * r * r);
}

TEST_CASE("ground truth of cylinders, oriented boxes and closed meshes agrees with inside tests",
          "[sim][ground_truth]") {
  const auto cell = sim::make_workcell();
  const iv::GridGeometry g(0.01);
  const auto keys = cell.scene.ground_truth(g, cell.objects);
  REQUIRE(keys.size() > 100);
  // Every voxel whose centre is inside a solid is occupied; a voxel whose whole box is far from
  // every object (a voxel's half diagonal) is not.
  const iv::KeyBox kb = g.key_box(cell.objects);
  iv::Key k;
  std::size_t inside_count = 0;
  for (k.x = kb.min.x; k.x <= kb.max.x; ++k.x)
    for (k.y = kb.min.y; k.y <= kb.max.y; ++k.y)
      for (k.z = kb.min.z; k.z <= kb.max.z; ++k.z) {
        const bool occ = std::binary_search(keys.begin(), keys.end(), k);
        if (cell.scene.inside(g.center(k))) {
          ++inside_count;
          REQUIRE(occ);
        }
      }
  CHECK(inside_count > 0);
  // The hole of the ring is free.
  CHECK_FALSE(cell.scene.occupied(g, g.key({0.75, 0.75, 0.755})));
  CHECK(cell.scene.occupied(g, g.key({0.80, 0.75, 0.755})));
  // The bottle (a cylinder of radius 3.5 cm at (0.95, 0.55)).
  CHECK(cell.scene.occupied(g, g.key({0.95, 0.55, 0.85})));
  CHECK_FALSE(cell.scene.occupied(g, g.key({0.95 + 0.05, 0.55, 0.85})));
}
