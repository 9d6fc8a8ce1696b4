// The gaps of seen walls (analysis/wall_gaps.hpp) on hand-built scenes, no simulator: the planted
// room split at x = 1 by a partition whose gap (y in [1.8, 3.2], up to 1.6 m) holds a mirror on
// its east face, is open into the strip behind, or is closed. The ray tracer folds a mirror's
// beams exactly, so the oracle is closed-form: a mirror's ends reflected about the partition's
// plane land on the surfaces they lit; a doorway's land where the room east of it is empty.
#include <intervox/analysis/wall_gaps.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"
#include "../common/planted_mirror_room.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace iv = intervox;

namespace wall_gaps_test {
using test::planted_mirror::Box;
using test::planted_mirror::Room;

constexpr double kRes = 0.05, kRange = 6.0;

enum class Gap { Mirror, Open, Closed };

// The planted room with its panel's rectangle (x = 1, y in [1.8, 3.2], z in [0, 1.6]) set in a
// partition x in [0.9, 1.0] from wall to wall and floor to ceiling: a mirror on the gap's east
// face, an open gap into the strip x in [0, 0.9], or a closed one.
Room partitioned_room(Gap gap) {
  Room room;
  room.panel = gap == Gap::Mirror;
  room.mirror = true;
  room.boxes.push_back(Box{{0.9, -0.1, 0.0}, {1.0, Room::kY0, 2.5}});             // south of the gap
  room.boxes.push_back(Box{{0.9, Room::kY1, 0.0}, {1.0, 5.1, 2.5}});              // north of it
  room.boxes.push_back(Box{{0.9, Room::kY0, Room::kZ1}, {1.0, Room::kY1, 2.5}});  // above it
  if (gap == Gap::Closed) room.boxes.push_back(Box{{0.9, Room::kY0, 0.0}, {1.0, Room::kY1, Room::kZ1}});
  return room;
}

// The room east of the partition scanned all around from its origins (every one lies there),
// into a channel (with its ledger, unless the options say otherwise).
iv::ExplainedSpace survey(const Room& room, const iv::ExplainOptions& options = {}) {
  iv::ExplainedSpace space(iv::GridGeometry(kRes), options);
  const iv::InsertOptions insert{.max_range = kRange};
  for (const iv::Point3& o : room.origins()) {
    std::vector<bool> phantom;
    const std::vector<iv::Beam> beams = room.scan_from(o, kRange, 0, 360, phantom);
    space.add(beams, space.classify(beams, insert), insert);
  }
  space.revise();
  return space;
}

// The gaps found in the partition's plane (x = 1 within a voxel).
std::vector<iv::WallGap> partition_gaps(const std::vector<iv::WallGap>& gaps) {
  std::vector<iv::WallGap> out;
  for (const iv::WallGap& g : gaps)
    if (std::abs(std::abs(g.surface.normal.x()) - 1.0) < 1e-3 && std::abs(g.surface.center.x() - 1.0) <= kRes)
      out.push_back(g);
  return out;
}

}  // namespace wall_gaps_test

namespace wg = wall_gaps_test;

TEST_CASE("a mirror set in a wall is a gap that may be a mirror: its phantom's ends reflect onto the surfaces they lit",
          "[analysis][lying][wall_gaps]") {
  const iv::ExplainedSpace space = wg::survey(wg::partitioned_room(wg::Gap::Mirror));
  const std::vector<iv::WallGap> gaps = wg::partition_gaps(iv::find_wall_gaps(space));
  REQUIRE(gaps.size() >= 1);
  // The largest gap holds the mirror: its patch lies in the mirror's rectangle (a voxel of slack
  // and the patch's half voxel), covers most of it, faces the room, and nothing contradicts it.
  const iv::WallGap& g =
      *std::max_element(gaps.begin(), gaps.end(), [](const auto& a, const auto& b) { return a.beams < b.beams; });
  CAPTURE(g.beams, g.votes, g.consistent, g.inconsistent, g.surface.center.transpose(), g.surface.half_u,
          g.surface.half_v);
  CHECK_FALSE(g.opening);
  CHECK(g.surface.normal.x() > 0.99);  // towards the room it was seen from
  CHECK(g.surface.center.y() - g.surface.half_u >= wg::Room::kY0 - 2 * wg::kRes);
  CHECK(g.surface.center.y() + g.surface.half_u <= wg::Room::kY1 + 2 * wg::kRes);
  CHECK(2.0 * g.surface.half_u >= 0.5 * (wg::Room::kY1 - wg::Room::kY0));
  CHECK(g.surface.center.z() + g.surface.half_v <= wg::Room::kZ1 + 2 * wg::kRes);
  CHECK(g.votes >= iv::WallGapParams{}.min_inconsistent);  // the shelf and crate faces, reflected
  CHECK(g.inconsistent * 100 <= g.consistent);
  for (const iv::WallGap& other : gaps) CHECK_FALSE(other.opening);
}

TEST_CASE("a doorway in a wall is an opening: what is seen through it, reflected, lands in space the room shows empty",
          "[analysis][lying][wall_gaps]") {
  const iv::ExplainedSpace space = wg::survey(wg::partitioned_room(wg::Gap::Open));
  const std::vector<iv::WallGap> gaps = wg::partition_gaps(iv::find_wall_gaps(space));
  REQUIRE(gaps.size() >= 1);
  const iv::WallGap& g =
      *std::max_element(gaps.begin(), gaps.end(), [](const auto& a, const auto& b) { return a.beams < b.beams; });
  CAPTURE(g.beams, g.votes, g.consistent, g.inconsistent);
  // The strip's west wall 0.9 m behind the gap folds to x = 1.9-2.0, where the room east of the
  // partition is empty.
  CHECK(g.opening);
  CHECK(g.inconsistent >= iv::WallGapParams{}.min_inconsistent);
}

TEST_CASE("a wall without a gap has none, and the gaps do not depend on the thread count",
          "[analysis][lying][wall_gaps][threaded]") {
  CHECK(wg::partition_gaps(iv::find_wall_gaps(wg::survey(wg::partitioned_room(wg::Gap::Closed)))).empty());

  const iv::ExplainedSpace space = wg::survey(wg::partitioned_room(wg::Gap::Mirror));
  iv::WallGapParams two;
  two.threads = 2;
  const std::vector<iv::WallGap> a = iv::find_wall_gaps(space), b = iv::find_wall_gaps(space, two);
  REQUIRE(a.size() == b.size());
  REQUIRE_FALSE(a.empty());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].opening == b[i].opening);
    CHECK(a[i].beams == b[i].beams);
    CHECK(a[i].consistent == b[i].consistent);
    CHECK(a[i].inconsistent == b[i].inconsistent);
    CHECK(a[i].surface.center == b[i].surface.center);
  }
}

TEST_CASE("a channel without a ledger finds no gap, and invalid wall-gap thresholds are refused",
          "[analysis][lying][wall_gaps]") {
  iv::ExplainOptions no_ledger;
  no_ledger.ledger_bytes = 0;
  const iv::ExplainedSpace space = wg::survey(wg::partitioned_room(wg::Gap::Mirror), no_ledger);
  CHECK(iv::find_wall_gaps(space).empty());

  const auto refuses = [&](auto change) {
    iv::WallGapParams p;
    change(p);
    CHECK_THROWS_AS(iv::find_wall_gaps(space, p), iv::InvalidArgument);
  };
  refuses([](iv::WallGapParams& p) { p.min_wall_area = 0.0; });
  refuses([](iv::WallGapParams& p) { p.min_wall_height = -1.0; });
  refuses([](iv::WallGapParams& p) { p.normal_step_deg = 0.0; });
  refuses([](iv::WallGapParams& p) { p.max_wall_tilt_deg = 90.0; });
  refuses([](iv::WallGapParams& p) { p.max_walls = 0; });
  refuses([](iv::WallGapParams& p) { p.min_inconsistent = 0; });
  refuses([](iv::WallGapParams& p) { p.opening_share = 1.0; });
}

TEMPLATE_TEST_CASE(
    "the explained planner with close_wall_gaps plans no pose and no path through a mirror set in a wall",
    "[plan][explained][wall_gaps]", test::BayesSparse, test::MeanDense, test::CompactBoundedSparse) {
  const wg::Room room = wg::partitioned_room(wg::Gap::Mirror);
  TestType grid = test::make_grid_for<TestType>(wg::kRes, iv::Bounds{{-3.0, -0.5, -0.5}, {5.0, 5.5, 3.0}});
  std::vector<std::vector<bool>> phantom;
  const std::vector<std::vector<iv::Beam>> scans = room.scans(wg::kRange, phantom);
  for (const bool close : {false, true}) {
    CAPTURE(close);
    iv::MobilePlannerParams p;
    test::planted_mirror::set_explained_params(p, wg::kRange);
    p.region.reset();  // unbounded: the region is derived from what was seen, phantom included
    p.explained.close_wall_gaps = close;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    const auto g = test::planted_mirror::map_of_scans(planner, grid, scans);
    // The robot stands at the first origin; look-around first, then plans.
    const iv::Pose at = iv::planar_pose(iv::Point3(3.5, 2.5, 0.0), 0.0);
    planner.plan(g, at);
    bool through = false;
    std::size_t closed = 0;
    for (int step = 0; step < 6; ++step) {
      const iv::MobilePlan r = planner.plan(g, at);
      for (const iv::WallGap& gap : r.wall_gaps) closed += gap.opening ? 0 : 1;
      if (!r.selected) break;
      for (const iv::Pose& q : r.path) through |= q.translation().x() < 1.0 + p.map.keep_out() - wg::kRes;
      through |= r.view.translation().x() < 1.0 + p.map.keep_out() - wg::kRes;
    }
    if (close) {
      CHECK(closed > 0);
      CHECK_FALSE(through);
    } else {
      CHECK(closed == 0);
    }
  }
}
