// Ground truth of conflict voxels from labelled beams (eval/conflict_scoring.hpp), on a scene of one solid
// box, x in [1, 2] m, y and z in [0, 1] m, at 0.1 m voxels.
#include <catch2/catch.hpp>
#include <intervox/analysis/conflicts.hpp>
#include <intervox/eval/conflict_scoring.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/sim/scene.hpp>

namespace iv = intervox;
using Path = iv::sim::BeamPath;

namespace {
iv::sim::Scene box_scene() {
  iv::sim::Scene s;
  s.add_box({{1.0, 0.0, 0.0}, {2.0, 1.0, 1.0}}, iv::sim::Material::diffuse(), "box");
  return s;
}
}  // namespace

TEST_CASE("a voxel is a true conflict where phantom data take part in contradicting evidence",
          "[analysis][conflicts][eval]") {
  const iv::sim::Scene scene = box_scene();
  const iv::GridGeometry g(0.1);
  iv::ConflictEvidence ev(g, scene, {{-1, -1, -1}, {5, 2, 2}}, 10.0);
  const iv::Point3 o(0.05, 0.55, 0.55);
  // A direct return from the box's face (voxel x = 10) and a reflected beam whose phantom end
  // lies behind the box (x = 30): its misses cross the box's voxels x = 10 ... 29.
  const std::vector<iv::Beam> beams{{o, {1.05, 0.55, 0.55}, true}, {o, {3.05, 0.55, 0.55}, true}};
  ev.add(beams, std::vector<Path>{Path::Direct, Path::Reflected});
  const auto& c = ev.counts();
  CHECK(c.at({10, 5, 5}).total == 2);
  CHECK(c.at({10, 5, 5}).hits == 1);
  CHECK(c.at({10, 5, 5}).phantom == 1);  // the reflected beam's miss in an occupied voxel
  CHECK(c.at({10, 5, 5}).truth == 1);    // the direct hit
  CHECK(c.at({5, 5, 5}).phantom == 0);   // free space crossed by both: agreeing misses
  CHECK(c.at({15, 5, 5}).phantom == 1);  // inside the box: a phantom miss only
  CHECK(c.at({20, 5, 5}).phantom == 0);  // just behind it (the box only touches this voxel): agreeing
  CHECK(c.at({30, 5, 5}).phantom == 1);  // the phantom hit in free space
  CHECK(ev.conflict_voxels() == std::vector<iv::Key>{{10, 5, 5}});  // the only voxel with hits and misses
  CHECK(ev.phantom_voxels().size() == 11);                          // x = 10 ... 19 and 30
  // A beam beyond the max range is cut there and carries misses only.
  iv::ConflictEvidence near(g, scene, {{-1, -1, -1}, {5, 2, 2}}, 0.5);
  near.add(std::vector<iv::Beam>{{o, {1.05, 0.55, 0.55}, true}}, std::vector<Path>{Path::Direct});
  CHECK(near.counts().count({10, 5, 5}) == 0);
  CHECK(near.counts().at({4, 5, 5}).hits == 0);
  CHECK_THROWS_AS(ev.add(beams, std::vector<Path>{Path::Direct}), iv::InvalidArgument);
}

TEST_CASE("the score counts flagged true conflicts and flagged surface-edge voxels", "[analysis][conflicts][eval]") {
  const iv::sim::Scene scene = box_scene();
  iv::IntervalGrid grid(0.1);
  iv::ConflictEvidence ev(grid.geometry(), scene, {{-1, -1, -1}, {5, 2, 2}}, 10.0);
  const iv::Point3 o(0.05, 0.55, 0.55);
  ev.add(std::vector<iv::Beam>{{o, {1.05, 0.55, 0.55}, true}, {o, {3.05, 0.55, 0.55}, true}},
         std::vector<Path>{Path::Direct, Path::Reflected});
  for (int x = 0; x < 12; ++x) grid.update(iv::Key{x, 5, 5}, iv::Observation::Miss);
  iv::ConflictReport rep;
  iv::ConflictRegion r;
  r.voxels = {{9, 5, 5}, {10, 5, 5}, {11, 5, 5}};
  rep.regions.push_back(r);
  const iv::ConflictScore s = iv::score_conflicts(grid, rep, ev);
  CHECK(s.flagged == 3);
  CHECK(s.truth == 1);
  CHECK(s.true_positive == 1);
  CHECK(s.near_positive == 3);
  CHECK(s.precision() == Approx(1.0 / 3));
  CHECK(s.recall() == 1.0);
  // Surface-edge voxels: observed, at or next to the box, without phantom evidence: x = 9 only
  // (x = 10 and 11 received phantom misses).
  CHECK(s.edge_voxels == 1);
  CHECK(s.edge_flagged == 1);
}
