// Planning on explained free space (MobilePlannerParams::explained) on hand-built scans, no
// simulator: a wall seen twice from the robot, then beams along the same lines that pass through
// it and end 1 m behind it (what a window or a mirror in the wall gives), and beams without a
// return. The explained planner's exploration map must trust none of the space behind the wall,
// and lose none of the space in front of it.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace iv = intervox;

namespace {
const iv::Point3 kFanOrigin(4.55, 2.05, 0.0);  // voxel centres (0.1 m voxels): no ray runs along a voxel face
constexpr double kFanWallX = 2.05;             // where the beams that meet the wall end (its voxels: [2.0, 2.1))
constexpr double kFanBehindX = 1.05;           // where the beams through it end
const iv::Bounds kFanRegion{{0.0, 0.0, 0.2}, {6.0, 4.0, 0.8}};

/// Horizontal beams from the robot's sensor column (every voxel layer of the band, 0.25-0.75 m)
/// towards -x, -20° to 20° in 1° steps (no column within the fan left out), ending at x = \p end_x,
/// with a return or without.
std::vector<iv::Beam> wall_fan(double end_x, bool hit) {
  std::vector<iv::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const double z = 0.25 + 0.1 * layer;
    for (int a = -20; a <= 20; ++a) {
      const double angle = a * std::numbers::pi / 180.0;
      const iv::Point3 origin(kFanOrigin.x(), kFanOrigin.y(), z);
      const iv::Point3 dir(-std::cos(angle), std::sin(angle), 0.0);
      beams.push_back({origin, origin + dir * ((kFanOrigin.x() - end_x) / std::cos(angle)), hit});
    }
  }
  return beams;
}

iv::MobilePlannerParams explained_params(bool explained, unsigned threads = 1) {
  iv::MobilePlannerParams p;
  p.region = kFanRegion;
  p.explained.enabled = explained;
  p.threads = threads;
  return p;
}

/// The map \p planner reads (its map_options()) of a copy of \p grid, inserting with a 4 m range.
template <class G>
iv::ExplainedMap<G> map_for(const iv::MobilePlanner& planner, const G& grid) {
  iv::InsertOptions insert;
  insert.max_range = 4.0;
  insert.threads = planner.params().threads;
  return iv::ExplainedMap<G>(grid, planner.map_options(), insert);
}

/// Inserts \p beams into every map, \p times scans.
template <class G>
void scan_all(std::initializer_list<iv::ExplainedMap<G>*> maps, const std::vector<iv::Beam>& beams, int times) {
  for (int i = 0; i < times; ++i)
    for (iv::ExplainedMap<G>* m : maps) m->insert(std::span<const iv::Beam>(beams));
}

/// The map cell of the column at (x, y).
iv::Cell2 column_at(const iv::ExplorationMap& map, const iv::GridGeometry& g, double x, double y) {
  return map.columns().cell_of_key(g.key(iv::Point3(x, y, 0.5)));
}
}  // namespace

TEMPLATE_TEST_CASE("the explained planner's map trusts no free space that only beams through a known wall gave",
                   "[plan][explained]", INTERVOX_TEST_GRIDS) {
  const TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  iv::MobilePlanner plain(iv::SensorRig::mobile_base(), explained_params(false));
  iv::MobilePlanner explained(iv::SensorRig::mobile_base(), explained_params(true));
  auto plain_map = map_for(plain, grid), explained_map = map_for(explained, grid);
  scan_all({&plain_map, &explained_map}, wall_fan(kFanWallX, true), 2);    // the wall, seen twice: a supported surface
  scan_all({&plain_map, &explained_map}, wall_fan(kFanBehindX, true), 3);  // then beams through it
  REQUIRE(explained_map.explained());
  CHECK_FALSE(plain_map.explained());
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  const iv::ExplorationMap pm = plain.exploration_map(plain_map, pose),
                           em = explained.exploration_map(explained_map, pose);
  const iv::GridGeometry& g = grid.geometry();
  // Behind the wall: only the beams through it crossed these voxels; they are suspect, so the
  // voxels are unexplained and their columns are not free, whatever the grid holds.
  for (const double x : {1.25, 1.55, 1.85}) {
    const iv::Key k = g.key(iv::Point3(x, 2.05, 0.45));
    CHECK(explained_map.explained()->state(k) == iv::ExplainedState::Unexplained);
    CHECK(explained_map.explained()->evidence(k).suspect_misses > 0);
    CHECK(explained_map.explained()->evidence(k).trusted_misses == 0);
    CHECK(em.columns().at(column_at(em, g, x, 2.05)) == iv::Occupancy::Unknown);
    CHECK(em.label(column_at(em, g, x, 2.05)) != iv::MapLabel::ReachableFree);
  }
  // In front of it: trusted misses explain the space, so the explained map is the grid's map.
  for (const double x : {2.55, 3.05, 3.55})
    CHECK(em.columns().at(column_at(em, g, x, 2.05)) == pm.columns().at(column_at(pm, g, x, 2.05)));
  if constexpr (std::is_same_v<typename TestType::UpdateType, iv::BayesLogOdds>) {
    // Three misses make a Bayes voxel free: the plain map trusts the space behind the wall.
    for (const double x : {1.25, 1.55, 1.85}) CHECK(pm.columns().at(column_at(pm, g, x, 2.05)) == iv::Occupancy::Free);
    CHECK(pm.columns().at(column_at(pm, g, 3.05, 2.05)) == iv::Occupancy::Free);
  }
}

TEST_CASE(
    "free space only beams without a return crossed is unknown to the explained planner's map, on a Bayes grid too",
    "[plan][explained][no-return]") {
  iv::MobilePlanner plain(iv::SensorRig::mobile_base(), explained_params(false));
  iv::MobilePlanner explained(iv::SensorRig::mobile_base(), explained_params(true));
  auto plain_map = map_for(plain, iv::BayesGrid(0.1)), explained_map = map_for(explained, iv::BayesGrid(0.1));
  // An absorbing surface ahead: no return, free up to the max range (4 m) in the grid.
  scan_all({&plain_map, &explained_map}, wall_fan(kFanBehindX, false), 3);
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  const iv::Cell2 ahead = column_at(plain.exploration_map(plain_map, pose), plain_map.geometry(), 3.05, 2.05);
  CHECK(plain.exploration_map(plain_map, pose).label(ahead) == iv::MapLabel::ReachableFree);
  CHECK(explained.exploration_map(explained_map, pose).columns().at(ahead) == iv::Occupancy::Unknown);
  CHECK(explained.exploration_map(explained_map, pose).label(ahead) != iv::MapLabel::ReachableFree);
  // Returns along the same lines explain the space: the column is free and reachable again.
  scan_all({&plain_map, &explained_map}, wall_fan(kFanWallX, true), 1);
  CHECK(explained.exploration_map(explained_map, pose).label(ahead) == iv::MapLabel::ReachableFree);
}

TEST_CASE("planning on explained free space reads a map with the channel: a plain grid or a map without it is refused",
          "[plan][explained]") {
  iv::BayesGrid grid(0.1);
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), explained_params(true));
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  CHECK_THROWS_WITH(planner.plan(grid, pose), Catch::Contains("ExplainedMap"));
  iv::ExplainedMapOptions without;
  without.explained = false;
  CHECK_THROWS_WITH(planner.plan(iv::ExplainedMap<iv::BayesGrid>(grid, without), pose),
                    Catch::Contains("explained channel"));
  const iv::MobilePlan first = planner.plan(planner.make_map(grid), pose);  // the look-around, on its map
  CHECK(first.reason == iv::ViewReason::Initial);
  iv::MobilePlannerParams gaps = explained_params(true);
  gaps.explained.close_wall_gaps = true;
  iv::ExplainedMapOptions no_gaps = iv::MobilePlanner(iv::SensorRig::mobile_base(), gaps).map_options();
  no_gaps.find_wall_gaps = false;
  CHECK_THROWS_WITH(
      iv::MobilePlanner(iv::SensorRig::mobile_base(), gaps).plan(iv::ExplainedMap<iv::BayesGrid>(grid, no_gaps), pose),
      Catch::Contains("find_wall_gaps"));
  iv::MobilePlannerParams bad = explained_params(true);
  bad.explained.explain.crossing_tolerance = -1.0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
}

TEST_CASE("an unbounded grid's derived region follows the trusted beams, not the voxels behind a known wall",
          "[plan][explained]") {
  iv::MobilePlannerParams pp = explained_params(false), ep = explained_params(true);
  pp.region.reset();
  ep.region.reset();
  iv::MobilePlanner plain(iv::SensorRig::mobile_base(), pp);
  iv::MobilePlanner explained(iv::SensorRig::mobile_base(), ep);
  auto plain_map = map_for(plain, iv::BayesGrid(0.1)), explained_map = map_for(explained, iv::BayesGrid(0.1));
  scan_all({&plain_map, &explained_map}, wall_fan(kFanWallX, true), 2);
  scan_all({&plain_map, &explained_map}, wall_fan(kFanBehindX, true), 3);
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  // The trusted beams end in the wall's voxels [2.0, 2.1): the region reaches region_margin
  // (0.5 m) beyond their centres; the grid's voxels reach back to the ends behind it, [1.0, 1.1).
  CHECK(explained.region_for(explained_map, pose).min.x() == Approx(2.05 - 0.5).margin(1e-9));
  CHECK(plain.region_for(plain_map, pose).min.x() == Approx(1.05 - 0.5).margin(1e-9));
}

TEST_CASE("the explained planner's evidence and map are the same for any thread count", "[plan][explained][threaded]") {
  const test::ThreadCap cap(3);
  iv::MobilePlanner one(iv::SensorRig::mobile_base(), explained_params(true, 1));
  iv::MobilePlanner three(iv::SensorRig::mobile_base(), explained_params(true, 3));
  auto g1 = map_for(one, iv::BayesGrid(0.1)), g3 = map_for(three, iv::BayesGrid(0.1));
  for (auto* g : {&g1, &g3}) {
    scan_all({g}, wall_fan(kFanWallX, true), 2);
    scan_all({g}, wall_fan(kFanBehindX, true), 2);
    scan_all({g}, wall_fan(kFanBehindX, false), 1);
  }
  std::vector<std::pair<iv::Key, iv::EvidenceCell>> a, b;
  g1.explained()->for_each([&](const iv::Key& k, const iv::EvidenceCell& c) { a.emplace_back(k, c); });
  g3.explained()->for_each([&](const iv::Key& k, const iv::EvidenceCell& c) { b.emplace_back(k, c); });
  REQUIRE(a.size() == b.size());
  REQUIRE_FALSE(a.empty());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].first == b[i].first);
    CHECK(a[i].second == b[i].second);
  }
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  const iv::ExplorationMap m1 = one.exploration_map(g1, pose), m3 = three.exploration_map(g3, pose);
  REQUIRE(m1.columns().size() == m3.columns().size());
  for (std::size_t i = 0; i < m1.columns().size(); ++i) {
    const iv::Cell2 c = m1.columns().cell_of(i);
    CHECK(m1.label(c) == m3.label(c));
  }
}

namespace explained_hazard_test {
/// A fan like wall_fan() from \p origin along \p dir_x (-1 or +1), 5 m long beams (cut at the
/// 4 m max range: trusted misses, no wall anywhere), without a return inside a narrow sector
/// (|angle| <= 3°): a black pillar on the axis absorbs the light of that sector.
/// \p widest: the largest angle on the +y side, \p lowest the smallest on the -y side (degrees).
std::vector<iv::Beam> fan_with_black_sector(const iv::Point3& origin_xy, double dir_x, int widest = 20,
                                            int lowest = -20) {
  std::vector<iv::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const iv::Point3 origin(origin_xy.x(), origin_xy.y(), 0.25 + 0.1 * layer);
    for (int a = lowest; a <= widest; ++a) {
      const double angle = a * std::numbers::pi / 180.0;
      const iv::Point3 dir(dir_x * std::cos(angle), std::sin(angle), 0.0);
      const bool black = std::abs(a) <= 3;
      beams.push_back({origin, origin + dir * (black ? 4.0 : 5.0), !black});
    }
  }
  return beams;
}

/// A panel behind the pillar (x in [1.0, 1.1), y in [1.9, 2.2), every band layer), seen straight
/// on from 0.6 m in front of it: a supported surface the black sector's beams pass within their
/// 4 m range, so they are suspect (ExplainedSpace: a beam without a return that went through a
/// surface the map supports).
std::vector<iv::Beam> panel_scan() {
  std::vector<iv::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const double z = 0.25 + 0.1 * layer;
    for (double y = 1.905; y < 2.2; y += 0.02) beams.push_back({{1.65, y, z}, {kFanBehindX, y, z}, true});
  }
  return beams;
}

/// The hazard tests' region: the lab floor from the panel on (what lies behind it is outside).
const iv::Bounds kPanelRegion{{1.0, 0.0, 0.2}, {6.0, 4.0, 0.8}};

/// Explained planning with unexplained hazards over kPanelRegion.
iv::MobilePlannerParams hazard_params() {
  iv::MobilePlannerParams p = explained_params(true);
  p.region = kPanelRegion;
  p.explained.unexplained_hazards = true;
  return p;
}

/// The unexplained lying region of \p r whose voxels hold \p k, or nullptr.
const iv::PlannedRegion* unexplained_region_with(const iv::MobilePlan& r, const iv::Key& k) {
  for (const iv::PlannedRegion& pr : r.regions)
    if (pr.unexplained && std::find(pr.region.voxels.begin(), pr.region.voxels.end(), k) != pr.region.voxels.end())
      return &pr;
  return nullptr;
}
}  // namespace explained_hazard_test

TEMPLATE_TEST_CASE(
    "with unexplained hazards the explained planner keeps its radius from a black pillar's columns that lying "
    "beams carved",
    "[plan][explained][hazard]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  iv::MobilePlannerParams hazards = explained_params(true);
  hazards.region = explained_hazard_test::kPanelRegion;
  iv::MobilePlannerParams plain = hazards;
  REQUIRE_FALSE(hazards.explained.unexplained_hazards);  // opt-in
  hazards.explained.unexplained_hazards = true;
  iv::MobilePlanner with(iv::SensorRig::mobile_base(), hazards);
  iv::MobilePlanner without(iv::SensorRig::mobile_base(), plain);
  auto with_map = map_for(with, grid), without_map = map_for(without, grid);
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  // The look-around places the start (its area, the rig's blind zone of 1.5 m, is the operator's
  // promise and no hazard): the corridor is a hazard from 1.5 m on.
  REQUIRE(with.plan(with_map, pose).reason == iv::ViewReason::Initial);
  REQUIRE(without.plan(without_map, pose).reason == iv::ViewReason::Initial);
  // The panel behind the pillar first, then the robot's fan towards -x: the pillar's sector carves
  // a corridor along y = 2.05 with beams that returned nothing though they passed the panel,
  // enclosed by the space the fan's other beams explain, the panel and the space in front of it.
  scan_all({&with_map, &without_map}, explained_hazard_test::panel_scan(), 6);
  scan_all({&with_map, &without_map}, explained_hazard_test::fan_with_black_sector(kFanOrigin, -1.0), 6);
  const iv::ExplorationMap hm = with.exploration_map(with_map, pose), fm = without.exploration_map(without_map, pose);
  const iv::GridGeometry& g = grid.geometry();
  const iv::ExplainedSpace& e = *with_map.explained();
  // The corridor, 1.5-2.5 m from the robot: unexplained, and unknown in both maps.
  for (const double x : {2.05, 2.55, 3.05}) {
    const iv::Key k = g.key(iv::Point3(x, 2.05, 0.45));
    REQUIRE(e.state(k) == iv::ExplainedState::Unexplained);
    CHECK(e.free_only_by_lying_beams(k));
    CHECK(e.evidence(k).suspect_misses > 0);
    CHECK(e.evidence(k).trusted_misses == 0);
    CHECK(hm.columns().at(column_at(hm, g, x, 2.05)) == iv::Occupancy::Unknown);
  }
  // Beside it, 0.3 m off its axis (within the robot's 0.36 m radius of it): explained free in both
  // maps; traversable under the first rule (the body would overlap the corridor), kept clear of
  // under the hazard rule.
  int beside = 0;
  for (const double x : {2.25, 2.55, 2.85})
    for (const double y : {1.75, 2.35}) {
      const iv::Cell2 c = column_at(hm, g, x, y);
      const iv::Cell2 axis = column_at(hm, g, x, 2.05);
      REQUIRE(hm.columns().at(axis) == iv::Occupancy::Unknown);
      if (hm.columns().at(c) != iv::Occupancy::Free) continue;  // the sector's edge rays may reach it
      ++beside;
      CHECK(fm.label(c) == iv::MapLabel::ReachableFree);
      CHECK(hm.label(c) != iv::MapLabel::ReachableFree);
      CHECK_FALSE(hm.reachable(c));
    }
  CHECK(beside >= 4);
  // Farther from the corridor than the robot's radius, the hazard takes nothing: the columns are
  // free in both maps and out of the hazard's reach.
  for (const double y : {1.35, 2.75}) {
    const iv::Cell2 c = column_at(hm, g, 2.55, y);
    CHECK(hm.columns().at(c) == iv::Occupancy::Free);
    CHECK(fm.columns().at(c) == iv::Occupancy::Free);
    CHECK(hm.label(c) != iv::MapLabel::MaybeCollision);
  }
}

TEST_CASE("with unexplained hazards, columns only beams without a return crossed, or open to unexplored space, stay a "
          "frontier of the explained planner, not a hazard",
          "[plan][explained][hazard]") {
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  // (a) No surface behind the pillar: its beams passed nothing the map supports, like the space
  // beyond the range at every border of what was seen. (b) The panel, but the fan has no beams
  // beside the pillar on its +y side: the corridor the lying beams carved is open to space no beam
  // explained (only its -y side is checked).
  for (const bool panel : {false, true}) {
    CAPTURE(panel);
    iv::BayesGrid grid(0.1);
    iv::MobilePlannerParams hazards = explained_params(true);
    hazards.region = explained_hazard_test::kPanelRegion;
    hazards.explained.unexplained_hazards = true;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), hazards);
    auto map = map_for(planner, grid);
    REQUIRE(planner.plan(map, pose).reason == iv::ViewReason::Initial);
    if (panel) scan_all({&map}, explained_hazard_test::panel_scan(), 6);
    scan_all({&map}, explained_hazard_test::fan_with_black_sector(kFanOrigin, -1.0, panel ? 3 : 20), 6);
    const iv::ExplorationMap m = planner.exploration_map(map, pose);
    const iv::GridGeometry& g = grid.geometry();
    const iv::Key k = g.key(iv::Point3(2.55, 2.05, 0.45));
    CHECK(map.explained()->state(k) == iv::ExplainedState::Unexplained);
    CHECK(map.explained()->free_only_by_lying_beams(k) == panel);
    int beside = 0;
    for (const double x : {2.25, 2.55, 2.85})
      for (const double y : {1.75, 2.35}) {
        const iv::Cell2 c = column_at(m, g, x, y);
        if (m.columns().at(c) != iv::Occupancy::Free) continue;
        ++beside;
        CHECK(m.label(c) == iv::MapLabel::ReachableFree);
      }
    CHECK(beside >= (panel ? 3 : 4));
  }
}

TEMPLATE_TEST_CASE(
    "with open group hazards, the explained planner keeps its radius from lying columns open to unexplored "
    "space too, and the frontier stays at their zone's edge",
    "[plan][explained][hazard]", INTERVOX_TEST_GRIDS) {
  // The open corridor of the test above (the panel, no beams beside the pillar on its +y side):
  // no occupied column near it, so without the option the body may stand over it.
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  iv::MobilePlannerParams off = explained_hazard_test::hazard_params();
  REQUIRE_FALSE(off.explained.open_group_hazards);  // opt-in
  iv::MobilePlannerParams on = off;
  on.explained.open_group_hazards = true;
  iv::MobilePlanner with(iv::SensorRig::mobile_base(), on), without(iv::SensorRig::mobile_base(), off);
  auto with_map = map_for(with, grid), without_map = map_for(without, grid);
  REQUIRE(with.plan(with_map, pose).reason == iv::ViewReason::Initial);
  REQUIRE(without.plan(without_map, pose).reason == iv::ViewReason::Initial);
  scan_all({&with_map, &without_map}, explained_hazard_test::panel_scan(), 6);
  scan_all({&with_map, &without_map}, explained_hazard_test::fan_with_black_sector(kFanOrigin, -1.0, 3), 6);
  const iv::ExplorationMap hm = with.exploration_map(with_map, pose), fm = without.exploration_map(without_map, pose);
  const iv::GridGeometry& g = grid.geometry();
  const iv::ExplainedSpace& e = *with_map.explained();
  const double keep_out = on.map.keep_out();
  // The lying columns (a band voxel free only by lying beams) beyond the start area, by brute force.
  std::vector<iv::Cell2> lying;
  const iv::KeyBox box = g.key_box(explained_hazard_test::kPanelRegion);
  for (std::int32_t y = box.min.y; y <= box.max.y; ++y)
    for (std::int32_t x = box.min.x; x <= box.max.x; ++x)
      for (std::int32_t z = box.min.z; z <= box.max.z; ++z)
        if (const iv::Key k{x, y, z};
            e.free_only_by_lying_beams(k) && (g.center(k) - kFanOrigin).head<2>().norm() > 1.6) {
          lying.push_back(hm.columns().cell_of_key(k));
          break;
        }
  REQUIRE(lying.size() >= 5);
  const auto distance_to_lying = [&](const iv::Cell2& c) {
    double d = 1e9;
    for (const iv::Cell2& l : lying) d = std::min(d, std::hypot(double(c.x - l.x), double(c.y - l.y)) * g.resolution());
    return d;
  };
  // With the option no reachable cell lies within the keep-out distance of a lying column; without
  // it some do (the body over the corridor), and the corridor is no hazard there.
  int reachable_near_without = 0, borders_at_edge = 0;
  for (std::size_t i = 0; i < hm.columns().size(); ++i) {
    const iv::Cell2 c = hm.columns().cell_of(i);
    const double d = distance_to_lying(c);
    if (d <= keep_out - 1e-9) {
      CHECK_FALSE(hm.reachable(c));
      if (fm.reachable(c)) ++reachable_near_without;
    } else if (d <= keep_out + 1.5 * g.resolution() && hm.label(c) == iv::MapLabel::Border) {
      ++borders_at_edge;
    }
  }
  CHECK(reachable_near_without >= 4);
  // The frontier is not hidden: cells just outside the zone are borders towards the corridor.
  CHECK(borders_at_edge >= 2);
  // Farther than the zone, both maps agree.
  for (std::size_t i = 0; i < hm.columns().size(); ++i) {
    const iv::Cell2 c = hm.columns().cell_of(i);
    if (distance_to_lying(c) > keep_out + 2 * g.resolution() && fm.label(c) == iv::MapLabel::ReachableFree)
      CHECK(hm.reachable(c));
  }
  // No lying region: the frontier rule handles an open group.
  const iv::MobilePlan r = with.plan(with_map, pose);
  for (const iv::PlannedRegion& pr : r.regions) CHECK_FALSE(pr.unexplained);
  // The view planned (if any) and its path keep the body off the corridor.
  for (const iv::Pose& q : r.scans)
    CHECK(distance_to_lying(hm.columns().cell_of_key(g.key(q.translation()))) > keep_out - 1e-9);
  for (const iv::Pose& q : r.path)
    CHECK(distance_to_lying(hm.columns().cell_of_key(g.key(q.translation()))) > keep_out - 1e-9);
}

TEMPLATE_TEST_CASE(
    "with unexplained hazards, an enclosed unexplained group is viewed from new directions, then retired, and "
    "the episode ends",
    "[plan][explained][hazard]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  iv::MobilePlannerParams params = explained_hazard_test::hazard_params();
  params.max_visits_per_frontier = 1;       // no new scans come in: a frontier once visited stays as it was
  REQUIRE_FALSE(params.conflicts.enabled);  // the groups are planned around without conflict-aware planning
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), params);
  auto map = map_for(planner, grid);
  iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  REQUIRE(planner.plan(map, pose).reason == iv::ViewReason::Initial);
  // The panel, then a fan of +-70° from the start with the black sector: the corridor is enclosed
  // by explained space wide enough to stand in and look at it from other directions.
  scan_all({&map}, explained_hazard_test::panel_scan(), 6);
  scan_all({&map}, explained_hazard_test::fan_with_black_sector(kFanOrigin, -1.0, 70, -70), 6);
  const iv::GridGeometry& g = grid.geometry();
  const iv::ConflictPlanningParams& cp = planner.params().conflicts;
  // The corridor the black sector carved (1.5-2.5 m from the robot, along y = 2.05).
  const auto corridor = [](const iv::MobilePlan& r) -> const iv::PlannedRegion* {
    for (const iv::PlannedRegion& pr : r.regions)
      if (pr.unexplained && pr.region.bounds.contains(iv::Point3(2.55, 2.05, 0.45))) return &pr;
    return nullptr;
  };
  int corridor_views = 0, open_calls = 0;
  iv::Termination end = iv::Termination::Running;
  for (int call = 0; call <= params.max_steps + 1 && end == iv::Termination::Running; ++call) {
    CAPTURE(call);
    const iv::MobilePlan r = planner.plan(map, pose);
    end = r.termination;
    REQUIRE(r.map);
    for (const iv::PlannedRegion& pr : r.regions) CHECK(pr.unexplained);  // conflict-aware planning is off
    const iv::PlannedRegion* c = corridor(r);
    REQUIRE(c);  // no scan explains it: it stays in every plan
    CHECK(c->directions == iv::distinct_directions(c->region.views, cp.min_angle));
    if (!c->unresolvable) {
      ++open_calls;
      CHECK(c->directions < cp.resolve_directions);
      CHECK(r.map->label(column_at(*r.map, g, 2.55, 2.05)) != iv::MapLabel::Unresolvable);
    }
    if (r.reason == iv::ViewReason::Conflict) {
      REQUIRE(r.conflict_region);
      const iv::PlannedRegion& aimed = r.regions[*r.conflict_region];
      CHECK(aimed.unexplained);
      CHECK_FALSE(aimed.unresolvable);
      // The view sees the group from a direction none of its views had.
      CHECK(iv::new_direction(aimed.region.centroid, planner.scan_origins().back(), aimed.region.views, cp.min_angle));
      corridor_views += &aimed == c;
    }
    // Safety: no view stands within the robot's radius of the group's voxels.
    if (!r.scans.empty()) {
      for (const iv::Key& k : c->region.voxels)
        CHECK((g.center(k) - r.view.translation()).head<2>().norm() > r.map->params().robot_radius);
      pose = r.view;
    }
  }
  CHECK(open_calls >= 1);
  CHECK(corridor_views >= 1);
  // The episode ends on its own, not on the budget.
  CHECK(end != iv::Termination::Running);
  CHECK(end != iv::Termination::Budget);
  // Retired: the next plan shows the group's columns with their own label, no frontier next to
  // it, and no other reason.
  const iv::MobilePlan last = planner.plan(map, pose);
  REQUIRE(last.map);
  const iv::PlannedRegion* c = corridor(last);
  REQUIRE(c);
  CHECK(c->unresolvable);
  CHECK(last.map->label(column_at(*last.map, g, 2.55, 2.05)) == iv::MapLabel::Unresolvable);
  const double zone =
      (last.map->params().keep_out() + std::max(cp.safety_margin, params.explained.unexplained_margin)) /
          last.map->resolution() +
      1.5;
  for (const iv::Cell2& b : last.map->borders())
    for (const iv::Key& k : c->region.voxels) {
      const iv::Cell2 q = last.map->columns().cell_of_key(k);
      CHECK(std::hypot(double(b.x - q.x), double(b.y - q.y)) > zone);
    }
  for (const iv::RefusedFrontier& f : last.refused) CHECK(f.reason != iv::FrontierRefusal::Unresolvable);
}

TEMPLATE_TEST_CASE(
    "with unexplained hazards, a lying region keeps only the unexplained columns within the hazard zone of "
    "its lying ones",
    "[plan][explained][hazard]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  const iv::MobilePlannerParams params = explained_hazard_test::hazard_params();
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), params);
  auto map = map_for(planner, grid);
  const iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  REQUIRE(planner.plan(map, pose).reason == iv::ViewReason::Initial);
  // The panel, then the fan of +-70° with the black sector (|angle| <= 3°, through the panel: the
  // lying corridor along y = 2.05) and beside it a wedge of beams without a return that pass no
  // surface (4° to 35°, cut at x = 2.25: a sensor that reports them short), then a wall at
  // x in [2.1, 2.2), y in [2.2, 3.7) seen from its far side, which closes the wedge. The wedge's
  // columns are unexplained but not lying, joined to the corridor, and enclosed.
  scan_all({&map}, explained_hazard_test::panel_scan(), 6);
  std::vector<iv::Beam> fan, wall;
  for (int layer = 0; layer < 6; ++layer) {
    const double z = 0.25 + 0.1 * layer;
    const iv::Point3 origin(kFanOrigin.x(), kFanOrigin.y(), z);
    for (int a = -70; a <= 70; ++a) {
      const double angle = a * std::numbers::pi / 180.0;
      const iv::Point3 dir(-std::cos(angle), std::sin(angle), 0.0);
      if (std::abs(a) <= 3)
        fan.push_back({origin, origin + dir * 4.0, false});
      else if (a >= 4 && a <= 35)
        fan.push_back({origin, origin + dir * ((kFanOrigin.x() - 2.25) / std::cos(angle)), false});
      else
        fan.push_back({origin, origin + dir * 5.0, true});  // cut at the 4 m range: trusted misses
    }
    for (double y = 2.21; y < 3.7; y += 0.02) wall.push_back({{0.9, y, z}, {2.15, y, z}, true});
  }
  scan_all({&map}, fan, 6);
  scan_all({&map}, wall, 6);
  const iv::GridGeometry& g = grid.geometry();
  const iv::ExplainedSpace& e = *map.explained();
  const iv::Key corridor = g.key(iv::Point3(2.55, 2.05, 0.45)), near = g.key(iv::Point3(2.55, 2.45, 0.45)),
                far = g.key(iv::Point3(2.45, 3.45, 0.45));
  REQUIRE(e.free_only_by_lying_beams(corridor));
  for (const iv::Key& k : {near, far}) {  // the wedge: unexplained, not lying
    REQUIRE(e.state(k) == iv::ExplainedState::Unexplained);
    REQUIRE_FALSE(e.free_only_by_lying_beams(k));
  }
  const iv::MobilePlan r = planner.plan(map, pose);
  REQUIRE(r.map);
  REQUIRE(r.map->columns().at(r.map->columns().cell_of_key(far)) == iv::Occupancy::Unknown);
  const iv::PlannedRegion* region = explained_hazard_test::unexplained_region_with(r, corridor);
  REQUIRE(region);
  const auto holds = [&](const iv::Key& k) {
    return std::find(region->region.voxels.begin(), region->region.voxels.end(), k) != region->region.voxels.end();
  };
  // 0.3 m from the corridor: part of the region; 1.3 m from it: not (farther than the robot's
  // radius + clearance + margin), where the beams ran out, left to the frontier rule.
  CHECK(holds(near));
  CHECK_FALSE(holds(far));
  // Every voxel of the region lies within that radius of a lying column.
  const double zone =
      (r.map->params().keep_out() + std::max(params.conflicts.safety_margin, params.explained.unexplained_margin)) /
      r.map->resolution();
  std::vector<iv::Cell2> lying;
  for (const iv::Key& k : region->region.voxels)
    if (e.free_only_by_lying_beams(k)) lying.push_back(r.map->columns().cell_of_key(k));
  std::size_t outside = 0;
  for (const iv::Key& k : region->region.voxels) {
    const iv::Cell2 q = r.map->columns().cell_of_key(k);
    double nearest = 1e9;
    for (const iv::Cell2& l : lying) nearest = std::min(nearest, std::hypot(double(l.x - q.x), double(l.y - q.y)));
    outside += nearest > zone + 1e-9;
  }
  CHECK(outside == 0);
  // The far column is no hazard: not given up, not in a lying region's zone.
  CHECK(r.map->label(r.map->columns().cell_of_key(far)) != iv::MapLabel::Unresolvable);
}

TEMPLATE_TEST_CASE(
    "with unexplained hazards, a frontier next to an open group that no candidate sees from a new direction is "
    "explored like any other, and the group is given up only when no frontier gives a view",
    "[plan][explained][hazard]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-1, -1, -1}, {7, 5, 3}});
  iv::MobilePlannerParams params = explained_hazard_test::hazard_params();
  params.max_visits_per_frontier = 1;
  // Directions count as distinct only if opposite: once seen, the group has no candidate from a
  // new direction anywhere.
  params.conflicts.min_angle = std::numbers::pi;
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), params);
  auto map = map_for(planner, grid);
  iv::Pose pose = iv::planar_pose(kFanOrigin, 0.0);
  REQUIRE(planner.plan(map, pose).reason == iv::ViewReason::Initial);
  scan_all({&map}, explained_hazard_test::panel_scan(), 6);
  scan_all({&map}, explained_hazard_test::fan_with_black_sector(kFanOrigin, -1.0, 70, -70), 6);
  const iv::Key corridor_key = grid.geometry().key(iv::Point3(2.55, 2.05, 0.45));
  const double reach = params.conflicts.region_reach / grid.geometry().resolution();
  int near_views = 0;
  bool given_up = false;
  iv::Termination end = iv::Termination::Running;
  for (int call = 0; call <= params.max_steps + 1 && end == iv::Termination::Running; ++call) {
    CAPTURE(call);
    const iv::MobilePlan r = planner.plan(map, pose);
    end = r.termination;
    REQUIRE(r.map);
    const iv::PlannedRegion* c = explained_hazard_test::unexplained_region_with(r, corridor_key);
    REQUIRE(c);
    CHECK(r.reason != iv::ViewReason::Conflict);  // never a view from a new direction
    for (const iv::RefusedFrontier& f : r.refused) CHECK(f.reason != iv::FrontierRefusal::NoNewDirection);
    if (c->unresolvable && !given_up) {
      given_up = true;
      CHECK_FALSE(r.selected);  // given up in a plan that found no view at all
    }
    if (!r.selected) continue;
    CHECK_FALSE(c->unresolvable);
    REQUIRE(r.frontier);
    // A frontier view next to the open group (within region_reach of its columns).
    bool near = false;
    for (const iv::Key& k : c->region.voxels) {
      const iv::Cell2 q = r.map->columns().cell_of_key(k);
      near = near || std::hypot(double(q.x - r.frontier->x), double(q.y - r.frontier->y)) <= reach;
    }
    near_views += near;
    pose = r.view;
  }
  CHECK(near_views >= 1);
  CHECK(given_up);
  CHECK(end != iv::Termination::Running);
  CHECK(end != iv::Termination::Budget);
}
