// Views that open passages (MobilePlannerParams::passage_views), on hand-built scans without the
// simulator: two rooms joined by a 1.2 m doorway. Room A was scanned nine times, room B through
// the doorway only once: B's voxels stay unknown for most updates, so the unknown columns beside
// the jambs close the doorway for the robot's radius and no frontier opens it. With passage views
// the planner aims at the doorway; scanning from the views it plans opens room B. (The thesis'
// lower rule calls B free after one miss and the upper rule occupied: no passage there.)
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"
#include "../common/planar_walls.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {
// Walls (each 3 m high): A is x 0-4, B x 4.1-7.1, both y 0-4; the wall between them (x 4.0-4.1)
// has the doorway y 1.4-2.6.
constexpr std::array<test::WallBox, 6> kWalls{{{-0.1, -0.1, 7.2, 0.0},  // south
                                               {-0.1, 4.0, 7.2, 4.1},   // north
                                               {-0.1, 0.0, 0.0, 4.0},   // west
                                               {7.1, 0.0, 7.2, 4.0},    // east
                                               {4.0, 0.0, 4.1, 1.4},    // the wall between, south of the doorway
                                               {4.0, 2.6, 4.1, 4.0}}};  // ... and north of it
const iv::Point3 kCentreA(2.05, 2.05, 0.0);                             // a voxel centre (0.1 m voxels)
const iv::Bounds kRegion{{-0.5, -0.5, 0.2}, {7.5, 4.5, 0.8}};

/// The band's beam fan from (x, y) (all walls lie within the 6 m range); without \p into_b only
/// the beams that end in room A (x < 4.1).
std::vector<iv::Beam> scan_from(double x, double y, bool into_b) {
  return test::planar_fan(kWalls, x, y,
                          [into_b](const iv::Point3&, const iv::Point3& end) { return into_b || end.x() < 4.1; });
}

/// One scan from room A's centre, B through the doorway included, then eight of room A alone
/// from its centre and from two points beside the doorway (beams into B left out), so that A's
/// voxels have nine misses (enough for every update) and B's one.
template <class G>
G scanned_rooms() {
  G grid = test::make_grid_for<G>(0.1, iv::Bounds{{-1.0, -1.0, -1.0}, {8.0, 5.0, 3.0}});
  iv::ScanInserter inserter({.max_range = 6.0});
  for (int i = 0; i < 9; ++i) {
    std::vector<iv::Beam> beams = scan_from(kCentreA.x(), kCentreA.y(), i < 1);
    if (i >= 2)
      for (const double y : {0.45, 3.65}) {
        const std::vector<iv::Beam> more = scan_from(3.75, y, false);
        beams.insert(beams.end(), more.begin(), more.end());
      }
    inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
  }
  return grid;
}

iv::MobilePlannerParams rooms_params(bool passages) {
  iv::MobilePlannerParams p;
  p.region = kRegion;
  p.threads = 1;
  p.passage_views.enabled = passages;
  return p;
}

/// True if some reachable cell of the plan's map lies in room B.
bool reaches_b(const iv::MobilePlan& plan, const iv::GridGeometry& g) {
  const iv::ExplorationMap& m = *plan.map;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x)
      if (m.reachable({x, y}) && iv::cell_center(m.columns(), g, {x, y}).x() > 4.2) return true;
  return false;
}
}  // namespace

TEMPLATE_TEST_CASE("a doorway seen by too few scans ends the plain exploration, and passage views open it",
                   "[plan][passage][typed]", INTERVOX_TEST_GRIDS) {
  TestType grid = scanned_rooms<TestType>();
  const iv::Pose pose = iv::planar_pose(kCentreA, 0.0);
  iv::MobilePlanner plain(iv::SensorRig::mobile_base(), rooms_params(false));
  REQUIRE(plain.plan(grid, pose).reason == iv::ViewReason::Initial);
  const iv::MobilePlan ended = plain.plan(grid, pose);
  // A voxel of B that one scan crossed: unknown for most updates, but the thesis' lower rule
  // calls it free and the upper rule occupied. Then the doorway is no passage (open, or walled
  // off), and passage views change nothing.
  if (grid.occupancy(iv::Point3(5.55, 2.05, 0.45)) != iv::Occupancy::Unknown) {
    iv::MobilePlanner with(iv::SensorRig::mobile_base(), rooms_params(true));
    with.plan(grid, pose);
    const iv::MobilePlan plan = with.plan(grid, pose);
    CHECK(plan.reason != iv::ViewReason::Passage);
    CHECK(plan.reason == ended.reason);
    CHECK(plan.termination == ended.termination);
    CHECK(plan.view.matrix() == ended.view.matrix());
    CHECK(reaches_b(ended, grid.geometry()) == (grid.occupancy(iv::Point3(5.55, 2.05, 0.45)) == iv::Occupancy::Free));
    return;
  }
  // Without passage views: no border, the episode ends with room B unknown.
  CHECK(ended.termination == iv::Termination::NoReachableFrontier);
  REQUIRE(ended.map);
  CHECK(ended.map->borders().empty());
  CHECK_FALSE(reaches_b(ended, grid.geometry()));

  // With them: views at the doorway until B is reachable, each from a reachable cell of its map,
  // on the passage ring, with every turn scanned `frames` times; then B's floor is frontier.
  const iv::MobilePlannerParams p = rooms_params(true);
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  REQUIRE(planner.plan(grid, pose).reason == iv::ViewReason::Initial);
  iv::ScanInserter inserter({.max_range = 6.0});
  iv::Pose at = pose;
  int passage_views = 0;
  bool opened = false;
  for (int step = 0; step < 8 && !opened; ++step) {
    const iv::MobilePlan plan = planner.plan(grid, at);
    REQUIRE(plan.map);
    if (reaches_b(plan, grid.geometry())) {
      opened = true;
      break;
    }
    REQUIRE(plan.termination == iv::Termination::Running);
    REQUIRE(plan.reason == iv::ViewReason::Passage);
    REQUIRE(plan.frontier);
    ++passage_views;
    const std::vector<iv::Cell2>& passages = plan.map->passages();
    CHECK(std::find(passages.begin(), passages.end(), *plan.frontier) != passages.end());
    const iv::Cell2 view_cell = plan.candidates[*plan.selected].cell;
    CHECK(plan.map->reachable(view_cell));
    const double d = std::hypot(double(view_cell.x - plan.frontier->x), double(view_cell.y - plan.frontier->y)) * 0.1;
    CHECK(d >= p.passage_views.ring.inner_radius - 1e-9);
    CHECK(d <= p.passage_views.ring.outer_radius + 1e-9);
    CHECK(plan.scans.size() == static_cast<std::size_t>(p.scans_per_view * p.passage_views.frames));
    CHECK(std::string(iv::to_string(plan.reason)) == "passage");
    // Scan from the view as often as the plan lists scans.
    at = plan.view;
    for (std::size_t s = 0; s < plan.scans.size(); ++s) {
      const std::vector<iv::Beam> beams = scan_from(at.translation().x(), at.translation().y(), true);
      inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
    }
  }
  CHECK(opened);
  CHECK(passage_views >= 1);
  CHECK(passage_views <= 3);
}

TEST_CASE("passage views do not depend on the thread count, and bad passage parameters throw", "[plan][passage]") {
  const iv::IntervalGrid grid = scanned_rooms<iv::IntervalGrid>();
  const iv::Pose pose = iv::planar_pose(kCentreA, 0.0);
  std::optional<iv::Pose> first;
  for (const unsigned threads : {1u, 2u}) {
    iv::MobilePlannerParams p = rooms_params(true);
    p.threads = threads;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    planner.plan(grid, pose);
    const iv::MobilePlan plan = planner.plan(grid, pose);
    REQUIRE(plan.reason == iv::ViewReason::Passage);
    if (!first)
      first = plan.view;
    else
      CHECK(plan.view.matrix() == first->matrix());
  }
  iv::MobilePlannerParams bad = rooms_params(true);
  bad.passage_views.frames = 0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
  bad = rooms_params(true);
  bad.passage_views.reach = 0.0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
  bad = rooms_params(true);
  bad.passage_views.min_hidden_area = -1.0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
  bad = rooms_params(true);
  bad.passage_views.ring.inner_radius = 3.0;
  bad.passage_views.ring.outer_radius = 2.0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
}
