// Why the mobile planner refused a frontier (MobilePlan::refused), on hand-built scans without the
// simulator: a round room of 2.5 m radius seen from its centre, with a 60° opening whose beams
// return nothing (free up to the 4 m max range, unknown beyond: the frontiers). Each reason is
// provoked by a parameter and checked, and every refusal's ring counts are checked against a
// brute-force count of the ring's cells.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"

#include <cmath>
#include <numbers>
#include <numeric>
#include <vector>

namespace iv = intervox;

namespace {
const iv::Point3 kRoomCentre(4.55, 2.05, 0.0);  // voxel centres of 0.1 m voxels
const iv::Bounds kRoomRegion{{0.0, -2.5, 0.2}, {9.0, 6.5, 0.8}};

/// Beams from the room's centre in every direction (1° steps, the six voxel layers of the band):
/// returns on the round wall, none through the opening (|angle| < 30°).
std::vector<iv::Beam> round_room() {
  std::vector<iv::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const iv::Point3 origin(kRoomCentre.x(), kRoomCentre.y(), 0.25 + 0.1 * layer);
    for (int a = -180; a < 180; ++a) {
      const double angle = a * std::numbers::pi / 180.0;
      const iv::Point3 dir(std::cos(angle), std::sin(angle), 0.0);
      const bool opening = std::abs(a) < 30;
      beams.push_back({origin, origin + dir * (opening ? 4.0 : 2.5), !opening});
    }
  }
  return beams;
}

template <class G>
G scanned_room() {
  G grid = test::make_grid_for<G>(0.1, iv::Bounds{{-1.0, -3.0, -1.0}, {10.0, 7.0, 3.0}});
  const std::vector<iv::Beam> beams = round_room();
  iv::ScanInserter inserter({.max_range = 4.0});
  for (int i = 0; i < 6; ++i)
    inserter.insert_beams(grid, std::span<const iv::Beam>(beams));  // enough misses for every policy
  return grid;
}

iv::MobilePlannerParams room_params() {
  iv::MobilePlannerParams p;
  p.region = kRoomRegion;
  p.threads = 1;
  return p;
}

/// The cells of the ring around f, by brute force over the square that holds it.
std::size_t ring_size(const iv::RingSamplerParams& ring, double res) {
  std::size_t n = 0;
  const int r = static_cast<int>(std::ceil(ring.outer_radius / res)) + 2;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const double d = std::hypot(double(dx), double(dy)) * res;
      n += d >= ring.inner_radius && d <= ring.outer_radius;
    }
  return n;
}

/// Every refusal's ring counts plus the ring's reachable cells make up the whole ring.
void check_ring_counts(const iv::MobilePlan& plan, const iv::RingSamplerParams& ring) {
  REQUIRE(plan.map);
  for (const iv::RefusedFrontier& f : plan.refused) {
    if (f.reason == iv::FrontierRefusal::Unresolvable || f.reason == iv::FrontierRefusal::Unexplained) continue;
    const std::size_t refused = std::accumulate(f.ring_refused.begin(), f.ring_refused.end(), std::size_t{0});
    CHECK(refused + iv::ring_cells(*plan.map, f.frontier, ring).size() == ring_size(ring, plan.map->resolution()));
    CHECK(f.ring_refused[static_cast<std::size_t>(iv::MapLabel::ReachableFree)] == 0);
    CHECK(f.ring_refused[static_cast<std::size_t>(iv::MapLabel::Border)] == 0);
  }
}
}  // namespace

TEMPLATE_TEST_CASE("a frontier whose best view gains too little is refused as low gain", "[plan][refusal][typed]",
                   INTERVOX_TEST_GRIDS) {
  const TestType grid = scanned_room<TestType>();
  iv::MobilePlannerParams p = room_params();
  const iv::Pose pose = iv::planar_pose(kRoomCentre, 0.0);
  // A reachable gain: the planner takes the opening's frontier, refusing nothing on the way.
  iv::MobilePlanner taking(iv::SensorRig::mobile_base(), p);
  REQUIRE(taking.plan(grid, pose).reason == iv::ViewReason::Initial);
  const iv::MobilePlan taken = taking.plan(grid, pose);
  REQUIRE(taken.termination == iv::Termination::Running);
  CHECK(taken.refused.empty());
  // No view can gain more than an unknown world's gain: every frontier tried is refused.
  p.min_relative_gain = 2.0;
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  planner.plan(grid, pose);
  const iv::MobilePlan plan = planner.plan(grid, pose);
  CHECK(plan.termination == iv::Termination::Explored);
  REQUIRE(!plan.refused.empty());
  CHECK(plan.refused.size() <= static_cast<std::size_t>(p.frontier_attempts));
  for (const iv::RefusedFrontier& f : plan.refused) {
    CHECK(f.reason == iv::FrontierRefusal::LowGain);
    CHECK(f.relative_gain >= 0.0);
    CHECK(f.relative_gain <= 1.0);
    CHECK(plan.map->label(f.frontier) == iv::MapLabel::Border);
  }
  CHECK(plan.refused.front().frontier == *taken.frontier);  // the closest frontier first, as when it was taken
  CHECK(plan.skipped > 0);
  check_ring_counts(plan, p.ring);
  CHECK(iv::to_string(plan.refused.front().reason) == "low gain");
}

TEST_CASE(
    "frontiers whose rings hold no reachable free cell are refused as having no candidate, and the plan is blocked",
    "[plan][refusal]") {
  const iv::BayesGrid grid = scanned_room<iv::BayesGrid>();
  iv::MobilePlannerParams p = room_params();
  // Frontiers and reachable cells lie within the 4 m the beams reach from the centre, so no two
  // are more than 8 m apart: every ring lies beyond the reachable room.
  p.ring.inner_radius = 8.5;
  p.ring.outer_radius = 9.0;
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  const iv::Pose pose = iv::planar_pose(kRoomCentre, 0.0);
  planner.plan(grid, pose);
  const iv::MobilePlan plan = planner.plan(grid, pose);
  CHECK(plan.termination == iv::Termination::Blocked);
  REQUIRE(!plan.refused.empty());
  for (const iv::RefusedFrontier& f : plan.refused) {
    CHECK(f.reason == iv::FrontierRefusal::NoCandidate);
    CHECK(iv::ring_cells(*plan.map, f.frontier, p.ring).empty());
    // Beyond the room's wall: unknown, collision space or unreachable, never a place to stand.
    CHECK(f.ring_refused[static_cast<std::size_t>(iv::MapLabel::Unknown)] > 0);
  }
  check_ring_counts(plan, p.ring);
}

TEST_CASE("a frontier selected as often as allowed is refused for its visit budget", "[plan][refusal]") {
  const iv::BayesGrid grid = scanned_room<iv::BayesGrid>();
  iv::MobilePlannerParams p = room_params();
  p.max_visits_per_frontier = 1;
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  const iv::Pose pose = iv::planar_pose(kRoomCentre, 0.0);
  planner.plan(grid, pose);
  const iv::MobilePlan first = planner.plan(grid, pose);
  REQUIRE(first.termination == iv::Termination::Running);
  REQUIRE(first.frontier);
  // The map did not change: the same frontier comes first again, and is refused.
  const iv::MobilePlan second = planner.plan(grid, pose);
  REQUIRE(!second.refused.empty());
  CHECK(second.refused.front().frontier == *first.frontier);
  CHECK(second.refused.front().reason == iv::FrontierRefusal::VisitBudget);
  CHECK(second.refused.front().relative_gain > p.min_relative_gain);  // it would still gain: the budget refused it
  if (second.frontier) {
    const iv::Cell2 d{second.frontier->x - first.frontier->x, second.frontier->y - first.frontier->y};
    CHECK(std::hypot(double(d.x), double(d.y)) * second.map->resolution() > p.frontier_radius);
  }
  check_ring_counts(second, p.ring);
}
