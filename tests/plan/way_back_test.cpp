// The way back (MobilePlannerParams::driven_paths), on hand-built scans without the simulator: a
// room 8 m x 3 m, a partition at x 4.0-4.1 with a doorway y 1.0-2.2. The robot looks around at S,
// the planner sends it through the doorway to a view V; then the map the robot plans on at V holds
// nothing of the doorway beside the jambs (the evidence there since turned unknown: here, a grid
// scanned so that no beam crossed those two boxes, the jambs' collision space), only the strip
// y 1.3-1.9 between them its path ran along. The unknown columns beside the jambs are in reach,
// and their maybe-collision zones cover the strip. Without the way back the robot is shut in at V; with it, the path it
// drove stays passable and S is reachable again, but no view stands on the strip.
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
#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace iv = intervox;

namespace {
const iv::Point3 kWbStart(1.05, 1.55, 0.0);  // a voxel centre (0.1 m voxels)
const iv::Bounds kWbRegion{{-0.5, -0.5, 0.2}, {8.5, 3.5, 0.8}};

/// The walls (3 m high): the room x 0-8, y 0-3 and the partition with its doorway.
constexpr std::array<test::WallBox, 6> kWbWalls{{{-0.1, -0.1, 8.1, 0.0},
                                                 {-0.1, 3.0, 8.1, 3.1},
                                                 {-0.1, 0.0, 0.0, 3.0},
                                                 {8.0, 0.0, 8.1, 3.0},
                                                 {4.0, 0.0, 4.1, 1.0},
                                                 {4.0, 2.2, 4.1, 3.0}}};
/// The two boxes of the doorway beside its jambs that no beam crosses in the map planned on at V.
constexpr std::array<test::WallBox, 2> kWbJambs{{{3.9, 1.0, 4.2, 1.3}, {3.9, 1.9, 4.2, 2.2}}};

/// Nine scans from each of \p points, of the beams \p keep accepts.
template <class G>
void wb_scan(G& grid, const std::vector<iv::Point3>& points,
             const std::function<bool(const iv::Point3&, const iv::Point3&)>& keep) {
  iv::ScanInserter inserter({.max_range = 9.0});
  for (int i = 0; i < 9; ++i)
    for (const iv::Point3& p : points) {
      const std::vector<iv::Beam> beams = test::planar_fan(kWbWalls, p.x(), p.y(), keep);
      inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
    }
}

iv::MobilePlannerParams wb_params(bool driven) {
  iv::MobilePlannerParams p;
  p.region = kWbRegion;
  p.threads = 1;
  p.driven_paths = driven;
  return p;
}

/// Beams that end west of x 6 (what the robot saw before it drove).
bool west_of_6(const iv::Point3&, const iv::Point3& end) { return end.x() < 6.0; }
/// Beams that cross neither box beside the jambs.
bool strip_only(const iv::Point3& a, const iv::Point3& b) {
  return std::none_of(kWbJambs.begin(), kWbJambs.end(),
                      [&](const test::WallBox& w) { return test::segment_meets(a, b, w); });
}

/// Scans from S, from 1 m before the doorway and from just behind it (beams ending west of x 6),
/// then plans from S (after the look-around), scanning from each view, until a view lies in room B
/// (x > 4.5, through the doorway); returns that plan, and in \p stops the positions scanned from
/// and \p before the grid they made.
template <class G>
iv::MobilePlan wb_drive_into_b(iv::MobilePlanner& planner, G& before, std::vector<iv::Point3>& stops) {
  stops = {kWbStart, {3.05, 1.55, 0.0}, {4.55, 1.55, 0.0}};
  wb_scan(before, stops, west_of_6);
  iv::Pose at = iv::planar_pose(kWbStart, 0.0);
  REQUIRE(planner.plan(before, at).reason == iv::ViewReason::Initial);
  for (int i = 0; i < 8; ++i) {
    iv::MobilePlan go = planner.plan(before, at);
    REQUIRE(go.reason == iv::ViewReason::Frontier);
    if (go.view.translation().x() > 4.5) return go;
    at = go.view;
    stops.push_back(at.translation());
    wb_scan(before, {at.translation()}, west_of_6);
  }
  FAIL("no view in room B within 8 plans");
  return {};
}

/// Drives \p planner into room B on an interval-mean grid (wb_drive_into_b), then plans at its
/// view on the map without evidence beside the jambs (scans from every stop and the view that
/// cross neither jamb box).
iv::MobilePlan wb_plan_back_at_view(iv::MobilePlanner& planner) {
  iv::IntervalGrid before(0.1), after(0.1);
  std::vector<iv::Point3> stops;
  const iv::MobilePlan go = wb_drive_into_b(planner, before, stops);
  stops.push_back(go.view.translation());
  wb_scan(after, stops, strip_only);
  return planner.plan(after, go.view);
}

/// The map cell of a point.
iv::Cell2 wb_cell_of(const iv::ExplorationMap& m, const iv::GridGeometry& g, const iv::Point3& p) {
  return m.columns().cell_of_key(g.key(iv::Point3(p.x(), p.y(), kWbRegion.min.z())));
}
}  // namespace

TEMPLATE_TEST_CASE("the way back: a robot shut in by zones found after it drove is not, and never stands on the way",
                   "[plan][way-back][typed]", INTERVOX_TEST_GRIDS) {
  const iv::Bounds box{{-1.0, -1.0, -1.0}, {9.0, 4.0, 3.0}};
  TestType before = test::make_grid_for<TestType>(0.1, box), before_off = test::make_grid_for<TestType>(0.1, box);
  iv::MobilePlanner with(iv::SensorRig::mobile_base(), wb_params(true));
  iv::MobilePlanner without(iv::SensorRig::mobile_base(), wb_params(false));
  std::vector<iv::Point3> stops, stops_off;
  const iv::MobilePlan go = wb_drive_into_b(with, before, stops);
  // The option changes nothing until a path was driven (and here no way back is needed yet).
  CHECK(wb_drive_into_b(without, before_off, stops_off).view.matrix() == go.view.matrix());
  const iv::Pose view = go.view;
  for (const iv::Pose& q : go.path)  // through the doorway along the strip between the jamb boxes
    if (q.translation().x() > 3.85 && q.translation().x() < 4.25) REQUIRE(strip_only(q.translation(), q.translation()));
  // What the robot plans on at the view: the same scans and the view's, but nothing beside the
  // jambs.
  TestType after = test::make_grid_for<TestType>(0.1, box);
  stops.push_back(view.translation());
  wb_scan(after, stops, strip_only);
  const iv::GridGeometry& g = after.geometry();
  // A voxel beside a jamb no beam crossed: the thesis' lower rule calls it free and the upper
  // occupied; then the boxes cut nothing (lower) or the way back through the doorway is in
  // collision space (upper), and there is no way back to take or none that helps.
  const iv::Occupancy band = after.occupancy(iv::Point3(4.05, 1.15, 0.45));
  const iv::MobilePlan shut = without.plan(after, view);
  const iv::MobilePlan back = with.plan(after, view);
  REQUIRE(shut.map);
  REQUIRE(back.map);
  // The cell the path to the view passed in the doorway (x 4.05).
  iv::Point3 door = go.path.front().translation();
  for (const iv::Pose& q : go.path)
    if (std::abs(q.translation().x() - 4.05) < std::abs(door.x() - 4.05)) door = q.translation();
  REQUIRE(std::abs(door.x() - 4.05) < 1e-9);
  const iv::Cell2 s = wb_cell_of(*back.map, g, kWbStart), mid = wb_cell_of(*back.map, g, door);
  if (band != iv::Occupancy::Unknown) {
    CHECK(back.map->reachable(s) == shut.map->reachable(s));
    return;
  }
  CHECK_FALSE(shut.map->passable(s));
  CHECK_FALSE(shut.map->passable(mid));
  CHECK(back.map->reachable(s));
  CHECK(back.map->passable(mid));
  CHECK_FALSE(back.map->reachable(mid));
  CHECK(back.map->label(mid) == shut.map->label(mid));
  CHECK(back.map->way_back_cells() > 0);
  // The path to S runs along the way back.
  const std::vector<iv::Cell2> path = back.map->path_to(s);
  REQUIRE_FALSE(path.empty());
  std::size_t on_way_back = 0;
  for (const iv::Cell2& c : path) on_way_back += back.map->passable(c) && !back.map->reachable(c) ? 1 : 0;
  CHECK(on_way_back >= 3);
  // No candidate of the plan stands on it.
  for (const iv::PlanarCandidate& c : back.candidates) CHECK(back.map->reachable(c.cell));

  // A robot that did not reach the view (given a pose 1 m south of it) takes no path as driven.
  TestType before_2 = test::make_grid_for<TestType>(0.1, box);
  iv::MobilePlanner elsewhere(iv::SensorRig::mobile_base(), wb_params(true));
  std::vector<iv::Point3> stops_2;
  wb_drive_into_b(elsewhere, before_2, stops_2);
  const iv::Pose off_view = iv::planar_pose(view.translation() - iv::Point3(0.0, 1.0, 0.0), 0.0);
  const iv::MobilePlan away = elsewhere.plan(after, off_view);
  REQUIRE(away.map);
  CHECK_FALSE(away.map->passable(mid));
}

TEST_CASE("the way back does not depend on the thread count, and a robot facing along its path takes none",
          "[plan][way-back]") {
  std::optional<iv::Pose> first;
  std::optional<std::size_t> cells;
  for (const unsigned threads : {1u, 2u}) {
    iv::MobilePlannerParams p = wb_params(true);
    p.threads = threads;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    const iv::MobilePlan back = wb_plan_back_at_view(planner);
    REQUIRE(back.map);
    if (!first) {
      first = back.view;
      cells = back.map->way_back_cells();
      CHECK(*cells > 0);
    } else {
      CHECK(back.view.matrix() == first->matrix());
      CHECK(back.map->way_back_cells() == *cells);
    }
  }
  // Facing along its path (turning on the spot on a driven cell would sweep more than the drive).
  iv::MobilePlannerParams facing = wb_params(true);
  facing.face_along_path = true;
  iv::MobilePlanner turner(iv::SensorRig::mobile_base(), facing);
  const iv::MobilePlan back = wb_plan_back_at_view(turner);
  REQUIRE(back.map);
  CHECK(back.map->way_back_cells() == 0);
}
