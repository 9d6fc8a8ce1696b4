// The safe-planner candidate (explained planning with unexplained and open-group hazards and
// closed wall gaps, docs/planning.md "Which options, as measured over 40 seeds" and "Gaps in a
// wall") in the planted scenes of examples/experiments/planted_scenes.hpp, each a room the lab
// room is not: a mirror on a wall (with the room's region, with its wall told, and in an unbounded
// grid with nothing told), a black box with a wall behind it, the open doorway between two
// mirror-symmetric rooms, a doorway into a deeper room, and a glass window with real things
// outside. All but the first are explored in an unbounded grid whose region the planner derives
// from what it saw. For each, the simulator's true scene is the oracle: no pose of the driven
// trajectory and no segment between two poses comes within the robot's radius (plus the map's
// clearance) of a true obstacle, the episode ends before its step budget, and at least 90 % of the
// reachable floor of the room it started in is known. Without close_wall_gaps the candidate drives
// through the wall mirror of the unbounded grid (checked below, so that the case can fail).
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include "../../examples/experiments/planted_scenes.hpp"

#include <cstddef>

namespace iv = intervox;
namespace ex = experiments;

TEMPLATE_TEST_CASE(
    "the safe-planner candidate never drives into a planted mirror, black box, doorway frame or window, and "
    "its episode ends",
    "[plan][explained][hazard][episode][slow]", iv::IntervalGrid, iv::BayesGrid) {
  for (const ex::Planted& planted : ex::planted_scenes()) {
    CAPTURE(planted.name);
    const ex::Outcome o = ex::explore<TestType>(planted, ex::safe_params(planted, 1), 1);
    CAPTURE(iv::to_string(o.termination), o.trajectory.size(), o.known, ex::met_names(o));
    CHECK(o.trajectory.size() > 1);  // it drove
    CHECK(o.known >= 0.9);           // and it explored the room it started in
    CHECK(o.collisions.poses == 0);
    CHECK(o.collisions.segments == 0);
    CHECK(o.met.empty());
    CHECK(o.termination != iv::Termination::Budget);
    CHECK(o.termination != iv::Termination::Running);
  }
}

TEST_CASE(
    "without closed wall gaps the candidate drives through a wall mirror in an unbounded grid, with them it stays out",
    "[plan][explained][hazard][episode][wall_gaps][slow]") {
  const ex::Planted planted = ex::mirror_wall(ex::MirrorTold::Nothing);
  const ex::Outcome open = ex::explore<iv::IntervalGrid>(planted, ex::safe_params(planted, 1, 1, false), 1);
  const ex::Outcome closed = ex::explore<iv::IntervalGrid>(planted, ex::safe_params(planted, 1, 1, true), 1);
  CAPTURE(ex::met_names(open), ex::met_names(closed), closed.gaps_closed);
  CHECK(open.collisions.poses > 0);
  CHECK(closed.collisions.poses == 0);
  CHECK(closed.collisions.segments == 0);
  CHECK(closed.gaps_closed > 0);
}

TEST_CASE("the safe-planner candidate drives the same trajectory in a planted scene on one thread and on two",
          "[plan][explained][hazard][episode][threaded][slow]") {
  const ex::Planted planted = ex::mirror_wall(ex::MirrorTold::Nothing);
  // Eight steps: enough for gaps to be closed and paths planned around them (the parallel wall
  // loop runs at every plan), and short under ThreadSanitizer.
  const auto params = [&](unsigned threads) {
    iv::MobilePlannerParams p = ex::safe_params(planted, 3, threads);
    p.max_steps = 8;
    return p;
  };
  const ex::Outcome one = ex::explore<iv::IntervalGrid>(planted, params(1), 3);
  const ex::Outcome two = ex::explore<iv::IntervalGrid>(planted, params(2), 3);
  CHECK(one.termination == two.termination);
  CHECK(one.gaps_closed == two.gaps_closed);
  CHECK(one.gaps_closed > 0);
  REQUIRE(one.trajectory.size() == two.trajectory.size());
  REQUIRE(one.trajectory.size() > 1);
  for (std::size_t i = 0; i < one.trajectory.size(); ++i) CHECK(one.trajectory[i].isApprox(two.trajectory[i], 0.0));
}
