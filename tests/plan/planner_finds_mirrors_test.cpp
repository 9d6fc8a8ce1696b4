// ExplainedPlanningParams::find_mirrors: the explained mobile planner finds the mirrors of its own
// evidence before it plans and tells its channel, on a planted mirror panel with closed-form
// phantoms (tests/common/planted_mirror_room.hpp, no simulator); off, the channel knows none.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/planted_mirror_room.hpp"

#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace iv = intervox;

TEST_CASE("with find_mirrors the map the explained mobile planner reads tells its channel of a planted mirror before "
          "the plan",
          "[plan][explained][lying]") {
  using test::planted_mirror::Room;
  const Room room;
  constexpr double kRange = 6.0;
  std::vector<std::vector<bool>> phantom;
  const auto scans = room.scans(kRange, phantom);
  for (const bool find : {false, true}) {
    iv::MobilePlannerParams p;
    test::planted_mirror::set_explained_params(p, kRange);
    p.explained.find_mirrors = find;
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    const auto map = test::planted_mirror::map_of_scans(planner, iv::VoxelGrid<iv::BayesLogOdds>(0.05), scans);
    (void)planner.plan(map, iv::planar_pose(iv::Point3(3.5, 2.5, 0.0), 0.0));
    const auto& grid = map.grid();
    const iv::ExplainedSpace& space = *map.explained();
    if (!find) {
      CHECK(space.mirrors().empty());
      continue;
    }
    // The panel's plane x = 1 (normal +x, towards the room), as the analysis finds it on its own.
    REQUIRE(space.mirrors().size() == 1);
    const iv::PlanePatch& m = space.mirrors().front();
    CHECK(m.normal.x() >= std::cos(3.0 * std::numbers::pi / 180.0));
    CHECK(std::abs(m.center.x() - Room::kPanelX) <= 0.05);
    CHECK(space.state(grid.geometry().key(iv::Point3(Room::kPanelX, 2.5, 0.5))) == iv::ExplainedState::Occupied);
  }
}
