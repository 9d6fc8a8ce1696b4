// The way back (MobilePlannerParams::driven_paths), on hand-built scans without the simulator: a
// room 8 m x 3 m. The robot looks around at S, the planner sends it east to a view V; then the
// map the robot plans on at V holds nothing of the band x 2.4-3.6 between them (the evidence
// there since turned unknown: here, a grid scanned so that no beam crossed it). Without the way
// back the robot is shut in at V; with it, the path it drove stays passable and S is reachable
// again, but no view stands on the band.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <vector>

namespace iv = intervox;

namespace {
const iv::Point3 kWbStart(1.05, 1.55, 0.0);  // a voxel centre (0.1 m voxels)
const iv::Bounds kWbRegion{{-0.5, -0.5, 0.2}, {8.5, 3.5, 0.8}};

/// The distance along (dx, dy) from (x, y) inside the room x 0-8, y 0-3 to its wall.
double wb_to_wall(double x, double y, double dx, double dy) {
  double t = std::numeric_limits<double>::infinity();
  if (dx > 1e-12) t = std::min(t, (8.0 - x) / dx);
  if (dx < -1e-12) t = std::min(t, (0.0 - x) / dx);
  if (dy > 1e-12) t = std::min(t, (3.0 - y) / dy);
  if (dy < -1e-12) t = std::min(t, (0.0 - y) / dy);
  return t;
}

/// Beams from (x, y) in 0.5° steps in the six voxel layers of the band, each ending 0.02 m inside
/// the wall, of those whose whole walk \p keep accepts (it is given the x of both ends).
std::vector<iv::Beam> wb_scan_from(double x, double y, const std::function<bool(double, double)>& keep) {
  std::vector<iv::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const iv::Point3 origin(x, y, 0.25 + 0.1 * layer);
    for (int a = 0; a < 720; ++a) {
      const double angle = a * std::numbers::pi / 360.0;
      const double dx = std::cos(angle), dy = std::sin(angle);
      const iv::Point3 end = origin + iv::Point3(dx, dy, 0.0) * (wb_to_wall(x, y, dx, dy) + 0.02);
      if (keep(origin.x(), end.x())) beams.push_back({origin, end, true});
    }
  }
  return beams;
}

/// Nine scans from each of \p points, of the beams \p keep accepts.
template <class G>
void wb_scan(G& grid, const std::vector<iv::Point3>& points, const std::function<bool(double, double)>& keep) {
  iv::ScanInserter inserter({.max_range = 9.0});
  for (int i = 0; i < 9; ++i)
    for (const iv::Point3& p : points) {
      const std::vector<iv::Beam> beams = wb_scan_from(p.x(), p.y(), keep);
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

/// The map cell of a point.
iv::Cell2 wb_cell_of(const iv::ExplorationMap& m, const iv::GridGeometry& g, const iv::Point3& p) {
  return m.columns().cell_of_key(g.key(iv::Point3(p.x(), p.y(), kWbRegion.min.z())));
}
}  // namespace

TEMPLATE_TEST_CASE("the way back: a robot that drove through space later unknown is not shut in, and never stands there",
                   "[plan][way-back][typed]", INTERVOX_TEST_GRIDS) {
  // What the robot saw before it drove: the room west of x 6 (beams that end there).
  TestType before = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1.0, -1.0, -1.0}, {9.0, 4.0, 3.0}});
  wb_scan(before, {kWbStart, {3.05, 1.55, 0.0}}, [](double, double end) { return end < 6.0; });
  const iv::Pose start = iv::planar_pose(kWbStart, 0.0);
  iv::MobilePlanner with(iv::SensorRig::mobile_base(), wb_params(true));
  iv::MobilePlanner without(iv::SensorRig::mobile_base(), wb_params(false));
  REQUIRE(with.plan(before, start).reason == iv::ViewReason::Initial);
  without.plan(before, start);
  const iv::MobilePlan go = with.plan(before, start);
  REQUIRE(go.reason == iv::ViewReason::Frontier);
  CHECK(without.plan(before, start).view.matrix() == go.view.matrix());  // the option changes nothing until a path was driven
  const iv::Pose view = go.view;
  REQUIRE(view.translation().x() > 3.8);  // the path crosses the band x 2.4-3.6
  // What the robot plans on at the view: nothing of the band (scans at S west of it, at V east).
  TestType after = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1.0, -1.0, -1.0}, {9.0, 4.0, 3.0}});
  wb_scan(after, {kWbStart}, [](double o, double end) { return o < 2.4 && end < 2.4; });
  wb_scan(after, {view.translation()}, [](double, double end) { return end > 3.6; });
  const iv::GridGeometry& g = after.geometry();
  // A voxel of the band no beam crossed: the thesis' lower rule calls it free and the upper
  // occupied; then the band cuts nothing (lower) or everything (upper), and there is no way back
  // to take or none that helps.
  const iv::Occupancy band = after.occupancy(iv::Point3(3.05, 1.55, 0.45));

  const iv::MobilePlan shut = without.plan(after, view);
  const iv::MobilePlan back = with.plan(after, view);
  REQUIRE(shut.map);
  REQUIRE(back.map);
  const iv::Cell2 s = wb_cell_of(*back.map, g, kWbStart), mid = wb_cell_of(*back.map, g, iv::Point3(3.05, 1.55, 0.0));
  if (band != iv::Occupancy::Unknown) {
    CHECK(back.map->way_back_cells() == 0);
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
  CHECK(on_way_back >= 10);  // the band is 1.2 m wide
  // No candidate of the plan stands on it.
  for (const iv::PlanarCandidate& c : back.candidates) CHECK(back.map->reachable(c.cell));

  // A robot that did not reach the view (given a pose 1 m south of it) takes no path as driven.
  iv::MobilePlanner elsewhere(iv::SensorRig::mobile_base(), wb_params(true));
  elsewhere.plan(before, start);
  elsewhere.plan(before, start);
  const iv::Pose off_view = iv::planar_pose(view.translation() - iv::Point3(0.0, 1.0, 0.0), 0.0);
  CHECK(elsewhere.plan(after, off_view).map->way_back_cells() == 0);
  // Nor a robot that faces along its path (turning on a driven cell sweeps more than driving did).
  iv::MobilePlannerParams facing = wb_params(true);
  facing.face_along_path = true;
  iv::MobilePlanner turner(iv::SensorRig::mobile_base(), facing);
  turner.plan(before, start);
  const iv::MobilePlan turn_go = turner.plan(before, start);
  REQUIRE(turn_go.reason == iv::ViewReason::Frontier);
  CHECK(turner.plan(after, turn_go.view).map->way_back_cells() == 0);
}

TEST_CASE("the way back does not depend on the thread count", "[plan][way-back]") {
  iv::IntervalGrid before(0.1), after(0.1);
  bool scanned = false;
  wb_scan(before, {kWbStart, {3.05, 1.55, 0.0}}, [](double, double end) { return end < 6.0; });
  const iv::Pose start = iv::planar_pose(kWbStart, 0.0);
  std::optional<iv::Pose> first;
  std::optional<std::size_t> cells;
  for (const unsigned threads : {1u, 2u}) {
    iv::MobilePlannerParams p = wb_params(true);
    p.threads = threads;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    planner.plan(before, start);
    const iv::MobilePlan go = planner.plan(before, start);
    REQUIRE(go.reason == iv::ViewReason::Frontier);
    if (!scanned) {
      wb_scan(after, {kWbStart}, [](double o, double end) { return o < 2.4 && end < 2.4; });
      wb_scan(after, {go.view.translation()}, [](double, double end) { return end > 3.6; });
      scanned = true;
    }
    const iv::MobilePlan back = planner.plan(after, go.view);
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
}
