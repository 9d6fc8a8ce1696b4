// floor_coverage (eval/ground_truth.hpp): the reachable floor of the true scene and the part of it a
// grid knows, over the whole region or over one part of it (the lab room's annex behind its
// doorway). Oracles: a room closed by its wall scores nothing beyond it, and parts that split the
// region add up to the whole.
#include <catch2/catch.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/sim/scenes.hpp>

#include <cstdint>

namespace iv = intervox;
using Approx = Catch::Detail::Approx;

namespace {
// The lab room and the annex east of it (x up to 11.2), at the planner's height band.
const iv::Bounds kFloor{{0.0, 0.0, 0.2}, {11.2, 6.6, 0.8}};
// The split at x = 8.0 falls between cell centres (0.1 m cells centred at .05).
const iv::Bounds kLabPart{{0.0, 0.0, 0.0}, {8.0, 6.6, 1.0}};
const iv::Bounds kAnnexPart{{8.0, 0.0, 0.0}, {11.2, 6.6, 1.0}};
}  // namespace

TEST_CASE("the floor coverage of a part counts only the reachable cells inside it, and parts add up to the whole",
          "[plan][coverage]") {
  iv::ExplorationMapParams map;
  map.robot_radius = 0.3;
  iv::BayesGrid grid(0.1);

  SECTION("a closed east wall leaves nothing reachable beyond it") {
    const iv::sim::LabRoom lab = iv::sim::make_lab_room();
    const iv::FloorCoverage beyond = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, kAnnexPart);
    CHECK(beyond.area == 0.0);
    CHECK(beyond.known == 1.0);  // nothing to know
    const iv::FloorCoverage inside = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, kLabPart);
    CHECK(inside.area == Approx(iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start).area));
    CHECK(inside.area > 20.0);
    CHECK(inside.known == 0.0);  // an empty grid knows nothing
  }

  SECTION("the annex behind the open doorway is reachable, and the grid's free columns are counted part by part") {
    iv::sim::LabRoomOptions o;
    o.annex = true;
    const iv::sim::LabRoom lab = iv::sim::make_lab_room(o);
    // The doorway and the west half of the annex (8.0 < x < 9.6) made free in the whole height band.
    const iv::GridGeometry& g = grid.geometry();
    const iv::KeyBox box = g.key_box(iv::Bounds{{8.01, 3.5, 0.0}, {9.59, 6.5, 1.0}});
    for (std::int32_t x = box.min.x; x <= box.max.x; ++x)
      for (std::int32_t y = box.min.y; y <= box.max.y; ++y)
        for (std::int32_t z = box.min.z; z <= box.max.z; ++z)
          for (int i = 0; i < 5; ++i) grid.update(iv::Key{x, y, z}, iv::Observation::Miss);
    const iv::Bounds west{{8.0, 0.0, 0.0}, {9.6, 6.6, 1.0}}, east{{9.6, 0.0, 0.0}, {11.2, 6.6, 1.0}};
    const auto whole = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start);
    const auto in_lab = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, kLabPart);
    const auto annex = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, kAnnexPart);
    const auto annex_west = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, west);
    const auto annex_east = iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, east);
    // The annex's inside is 3.0 x 3.0 m; its walls, shelf and crate grown by the radius take part of it.
    CHECK(annex.area > 3.0);
    CHECK(annex.area < 9.0);
    CHECK(whole.area == Approx(in_lab.area + annex.area));
    CHECK(annex.area == Approx(annex_west.area + annex_east.area));
    CHECK(annex_west.known == 1.0);
    CHECK(annex_east.known == 0.0);
    CHECK(annex.known * annex.area == Approx(annex_west.area));
    CHECK(whole.known * whole.area == Approx(annex_west.area));
    CHECK(in_lab.known == 0.0);
  }

  SECTION("an invalid part is refused") {
    const iv::sim::LabRoom lab = iv::sim::make_lab_room();
    const iv::Bounds inverted{{9.0, 0.0, 0.0}, {8.0, 6.6, 1.0}};
    CHECK_THROWS_AS(iv::floor_coverage(grid, lab.scene, kFloor, map, lab.start, inverted), iv::InvalidArgument);
  }
}
