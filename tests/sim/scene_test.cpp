// The built-in scenes: the lab room's layout, ground truth, free-floor connectivity, the workcell.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <deque>
#include <vector>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

TEST_CASE("the lab room is an 8 x 6 x 3 m room with the chosen closet material", "[sim][scene]") {
  sim::LabRoomOptions o;
  o.closet_material = sim::Material::absorbing(0.1);
  const auto lab = sim::make_lab_room(o);
  const auto b = lab.scene.bounds();
  CHECK((b.min - Point3(-0.1, -0.1, -0.1)).norm() < 1e-12);
  CHECK((b.max - Point3(8.1, 6.1, 3.1)).norm() < 1e-12);
  CHECK(lab.scene.material(lab.closet).surface == sim::Surface::Absorbing);
  CHECK(lab.scene.material(lab.closet).p_return == 0.1);
  CHECK(lab.scene.name(lab.closet) == "closet");
  CHECK(lab.scene.shape(lab.door) == sim::ShapeKind::Quad);
  for (const char* name : {"desk_island", "trash_can", "barrier_1", "cabinet", "globe", "closet_north_1"})
    CHECK(lab.scene.find(name).has_value());
  // The closet stands against the west wall, in front of it with a 1 mm gap.
  CHECK(lab.scene.inside({0.3, 4.0, 1.0}));
  CHECK_FALSE(lab.scene.inside({0.0005, 4.0, 1.0}));
  CHECK(lab.scene.inside({-0.05, 4.0, 1.0}));
  // The start is free for the base's footprint (0.6 x 0.4 m, any yaw: a 0.72 m square) up to 1 m.
  CHECK_FALSE(lab.scene.overlaps({lab.start + Point3(-0.36, -0.36, 0.01), lab.start + Point3(0.36, 0.36, 1.0)}));
}

TEST_CASE("the lab room's free floor is connected for the base", "[sim][scene]") {
  const auto lab = sim::make_lab_room();
  // A cell is free if a disc of the base's inscribed radius (0.2 m, as a square) fits at knee
  // heights 0.01..1 m. Every free cell must be reachable from the start.
  const double res = 0.05, r = 0.2;
  const int nx = 160, ny = 120;
  std::vector<char> free(nx * ny, 0), seen(nx * ny, 0);
  int free_count = 0;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const Point3 c((x + 0.5) * res, (y + 0.5) * res, 0);
      free[y * nx + x] = !lab.scene.overlaps({c + Point3(-r, -r, 0.01), c + Point3(r, r, 1.0)});
      free_count += free[y * nx + x];
    }
  const int sx = static_cast<int>(lab.start.x() / res), sy = static_cast<int>(lab.start.y() / res);
  REQUIRE(free[sy * nx + sx]);
  std::deque<int> q{sy * nx + sx};
  seen[sy * nx + sx] = 1;
  int reached = 0;
  while (!q.empty()) {
    const int c = q.front();
    q.pop_front();
    ++reached;
    const int x = c % nx, y = c / nx;
    const int nb[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (const auto& d : nb) {
      const int X = x + d[0], Y = y + d[1];
      if (X < 0 || Y < 0 || X >= nx || Y >= ny) continue;
      const int i = Y * nx + X;
      if (free[i] && !seen[i]) {
        seen[i] = 1;
        q.push_back(i);
      }
    }
  }
  CHECK(reached == free_count);
  CHECK(free_count > nx * ny / 2);  // most of the floor is free
}

TEST_CASE("the lab room's ground truth holds walls and furniture, not the free interior",
          "[sim][scene][ground_truth]") {
  const auto lab = sim::make_lab_room();
  const iv::GridGeometry g(0.1);
  const auto keys = lab.scene.ground_truth(g, lab.scene.bounds());
  const auto occupied = [&](const Point3& p) { return std::binary_search(keys.begin(), keys.end(), g.key(p)); };
  CHECK(occupied({-0.05, 3.0, 1.5}));  // west wall
  CHECK(occupied({4.0, 3.0, -0.05}));  // floor
  CHECK(occupied({0.3, 4.0, 1.0}));    // closet
  CHECK(occupied({4.3, 0.3, 0.2}));    // trash can
  CHECK(occupied({5.0, 3.0, 0.88}));   // globe
  CHECK_FALSE(occupied({6.0, 1.5, 0.5}));
  CHECK_FALSE(occupied({4.0, 3.0, 2.0}));
  // Interior layer z in [0, 0.1): every key agrees with occupied(key).
  const auto in = lab.scene.ground_truth(g, {{0, 0, 0}, {8, 6, 0.1}});
  std::size_t count = 0;
  iv::Key k{0, 0, 0};
  for (k.x = 0; k.x < 80; ++k.x)
    for (k.y = 0; k.y < 60; ++k.y) {
      const bool o = lab.scene.occupied(g, k);
      count += o;
      REQUIRE(std::binary_search(in.begin(), in.end(), k) == o);
    }
  CHECK(count == in.size());
  CHECK(count > 100);
  CHECK(count < 80 * 60 / 2);
}

TEST_CASE("the workcell holds a specular ring, a transparent bottle and a box on a table", "[sim][scene]") {
  const auto cell = sim::make_workcell();
  CHECK(cell.scene.material(cell.part).surface == sim::Surface::Specular);
  CHECK(cell.scene.material(cell.bottle).surface == sim::Surface::Transparent);
  CHECK(cell.scene.material(cell.bottle_neck).surface == sim::Surface::Transparent);
  CHECK(cell.scene.material(cell.box).surface == sim::Surface::Diffuse);
  CHECK(cell.scene.shape(cell.part) == sim::ShapeKind::Mesh);
  CHECK(cell.scene.solid(cell.part));
  const auto b = cell.scene.bounds();
  CHECK((b.max - b.min).maxCoeff() == Approx(1.52));
  // Looking straight down at the ring's centre: the hole shows the table top at 0.74 m.
  const auto hole = cell.scene.intersect({0.75, 0.75, 1.5}, {0, 0, -1});
  REQUIRE(hole);
  CHECK(hole->object == cell.table);
  CHECK(hole->t == Approx(1.5 - 0.74));
  const auto rim = cell.scene.intersect({0.80, 0.75, 1.5}, {0, 0, -1});
  REQUIRE(rim);
  CHECK(rim->object == cell.part);
  CHECK(rim->t == Approx(1.5 - 0.77));
  sim::WorkcellOptions o;
  o.part_material = sim::Material::diffuse();
  CHECK(sim::make_workcell(o).scene.material(cell.part).surface == sim::Surface::Diffuse);
}

TEST_CASE("degenerate primitives are rejected with a clear error", "[sim][scene][errors]") {
  sim::Scene s;
  const double nan = std::nan("");
  CHECK_THROWS_AS(s.add_box({{0, 0, 0}, {1, 0, 1}}), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_box({{0, 0, 0}, {1, nan, 1}}), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_sphere({0, 0, 0}, 0.0), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_sphere({nan, 0, 0}, 1.0), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_cylinder({0, 0, 0}, {0, 0, 0}, 1.0), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_cylinder({0, 0, 0}, {0, 0, 1}, -1.0), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_quad({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), iv::InvalidArgument);
  CHECK_THROWS_AS(s.add_oriented_box(iv::Pose::Identity(), {1, 0, 1}), iv::InvalidArgument);
  sim::TriangleMesh m;
  CHECK_THROWS_AS(s.add_mesh(m), iv::InvalidArgument);
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  m.triangles = {{0, 1, 2}};
  CHECK_THROWS_AS(s.add_mesh(m), iv::InvalidArgument);  // zero area
  m.triangles = {{0, 1, 3}};
  CHECK_THROWS_AS(s.add_mesh(m), iv::InvalidArgument);  // missing vertex
  CHECK_THROWS_AS(sim::make_ring({0, 0, 0}, 0.1, 0.05, 0.1), iv::InvalidArgument);
  CHECK(s.size() == 0);
  CHECK_THROWS_AS(s.inside({nan, 0, 0}), iv::InvalidArgument);
  CHECK_FALSE(s.intersect({nan, 0, 0}, {1, 0, 0}).has_value());
  try {
    s.add_sphere({0, 0, 0}, 0.0);
  } catch (const iv::Error& e) {
    CHECK(std::string(e.what()).find("sphere radius") != std::string::npos);
  }
}

TEST_CASE("a voxel's occupants are the objects whose ground truth holds it", "[sim][scene][ground_truth]") {
  iv::sim::Scene s;
  const iv::sim::ObjectId a = s.add_box({{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}}, {}, "a");
  const iv::sim::ObjectId b =
      s.add_box({{0.98, 0.0, 0.0}, {2.0, 1.0, 1.0}}, {}, "b");  // overlaps a's last voxel column
  const iv::sim::ObjectId q = s.add_quad({0.0, 2.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, {}, "quad");
  const iv::GridGeometry g(0.1);
  const iv::Bounds all{{-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}};
  const auto truth = s.ground_truth(g, all);
  // occupants() is non-empty exactly on the ground truth's voxels (brute force over the region).
  const iv::KeyBox box = g.key_box(all);
  std::size_t occupied = 0;
  iv::Key k;
  for (k.x = box.min.x; k.x <= box.max.x; ++k.x)
    for (k.y = box.min.y; k.y <= box.max.y; ++k.y)
      for (k.z = box.min.z; k.z <= box.max.z; ++k.z) {
        const auto o = s.occupants(g, k);
        CHECK(o.empty() != std::binary_search(truth.begin(), truth.end(), k));
        occupied += !o.empty();
      }
  CHECK(occupied == truth.size());
  CHECK(s.occupants(g, g.key({0.55, 0.55, 0.55})) == std::vector<iv::sim::ObjectId>{a});
  CHECK(s.occupants(g, g.key({0.95, 0.55, 0.55})) == std::vector<iv::sim::ObjectId>{a, b});
  CHECK(s.occupants(g, g.key({1.55, 0.55, 0.55})) == std::vector<iv::sim::ObjectId>{b});
  CHECK(s.occupants(g, g.key({0.55, 2.0, 0.55})) == std::vector<iv::sim::ObjectId>{q});
  CHECK(s.occupants(g, g.key({2.3, 2.3, 0.55})).empty());
}
