// ExplainedPlanningParams::known_surfaces: the surfaces a user knows are told to the planner's
// channel as it is made (kept as given), so every beam through one is suspect from the first scan
// on and its voxels are explained occupied; on the planted mirror panel with closed-form phantoms
// (tests/common/planted_mirror_room.hpp, no simulator), for both planners' parameters; invalid
// surfaces are refused when the planner is made; the arm planner tells its channel of them too.
#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include "../common/planted_mirror_room.hpp"

#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace iv = intervox;

namespace {

using test::planted_mirror::Room;

// The panel's mirror face as its owner knows it: x = 1, y in [1.8, 3.2], z in [0, 1.6].
iv::PlanePatch known_panel() {
  iv::PlanePatch p;
  p.center = iv::Point3(Room::kPanelX, 0.5 * (Room::kY0 + Room::kY1), 0.5 * Room::kZ1);
  p.normal = iv::Point3::UnitX();
  p.axis_u = iv::PlanePatch::floor_axis(p.normal);
  p.half_u = 0.5 * (Room::kY1 - Room::kY0);
  p.half_v = 0.5 * Room::kZ1;
  return p;
}

}  // namespace

TEST_CASE(
    "a known surface makes every beam through it suspect from the first scan on, and its voxels explained occupied",
    "[plan][explained][mirror]") {
  const Room room;
  constexpr double kRange = 6.0;
  std::vector<std::vector<bool>> phantom;
  const auto scans = room.scans(kRange, phantom);
  const iv::PlanePatch panel = known_panel();
  const double tol = iv::ExplainOptions{}.crossing_tolerance;
  for (const bool known : {false, true}) {
    INFO((known ? "panel known" : "panel unknown"));
    iv::MobilePlannerParams p;
    test::planted_mirror::set_explained_params(p, kRange);
    if (known) p.explained.known_surfaces = {panel};
    iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
    const auto map = test::planted_mirror::map_of_scans(planner, iv::VoxelGrid<iv::BayesLogOdds>(0.05), scans);
    const iv::ExplainedSpace& space = *map.explained();
    // Oracle: the closed-form phantoms. Every phantom that crosses the panel more than the
    // crossing tolerance before its end is suspect when the panel is known (unknown, some pass as
    // trusted: they cross no surface the beams saw).
    std::size_t crossing = 0, suspect = 0;
    REQUIRE(space.ledger().scans().size() == scans.size());
    for (std::size_t s = 0; s < scans.size(); ++s)
      space.ledger().scans()[s].for_each([&](std::size_t i, const iv::Beam& b, iv::BeamClass c) {
        const auto t = panel.crossing(b.origin, b.end);
        if (!phantom[s][i] || !b.hit || !t || (1.0 - *t) * (b.end - b.origin).norm() <= tol) return;
        ++crossing;
        suspect += c == iv::BeamClass::Suspect ? 1 : 0;
      });
    REQUIRE(crossing > 1000);
    if (known) {
      CHECK(suspect == crossing);
      REQUIRE(space.mirrors().size() == 1);
      CHECK(space.mirrors().front().center == panel.center);
    } else {
      CHECK(crossing - suspect > crossing / 4);  // measured: 3,131 of 6,695 trusted
      CHECK(space.mirrors().empty());
    }
    // The panel's voxels (the mirror reflects: no direct return marks them).
    const iv::Key on_panel = map.geometry().key(iv::Point3(Room::kPanelX + 0.01, 2.5, 0.5));
    CHECK((space.state(on_panel) == iv::ExplainedState::Occupied) == known);
  }
}

TEST_CASE("invalid known surfaces are refused when a planner is made", "[plan][explained][errors]") {
  iv::PlanePatch bad = known_panel();
  bad.normal = iv::Point3(0.0, 0.0, 2.0);
  iv::MobilePlannerParams mp;
  mp.explained.enabled = true;
  mp.explained.known_surfaces = {known_panel(), bad};
  CHECK_THROWS_WITH(iv::MobilePlanner(iv::SensorRig::mobile_base(), mp), Catch::Contains("unit vector"));
  iv::ArmPlannerParams ap;
  ap.explained.enabled = true;
  ap.explained.known_surfaces = {bad};
  CHECK_THROWS_WITH(ap.validate(), Catch::Contains("unit vector"));
}

TEST_CASE("the arm planner's map tells its channel of the known surfaces too", "[plan][explained][mirror][arm]") {
  // A polished panel the user knows, x = 0.3 m (y, z in [-0.1, 0.1]), and one fan of returns from
  // the origin onto a backdrop at x = 0.6 m: those through the panel are suspect, the others trusted.
  iv::PlanePatch panel;
  panel.center = iv::Point3(0.3, 0.0, 0.0);
  panel.normal = -iv::Point3::UnitX();
  panel.axis_u = iv::PlanePatch::floor_axis(panel.normal);
  panel.half_u = 0.1;
  panel.half_v = 0.1;
  std::vector<iv::Beam> fan;
  for (double y = -0.3; y <= 0.3; y += 0.01) fan.push_back({iv::Point3::Zero(), iv::Point3(0.6, y, 0.0), true});
  iv::ArmPlannerParams p;
  p.explained.enabled = true;
  p.explained.known_surfaces = {panel};
  iv::ArmPlanner planner(iv::SensorRig::arm(), p);
  auto map = planner.make_map(iv::VoxelGrid<iv::BayesLogOdds>(0.01));
  map.insert(std::span<const iv::Beam>(fan));
  REQUIRE(map.explained());
  const iv::ExplainedSpace& space = *map.explained();
  const auto& grid = map.grid();
  REQUIRE(space.mirrors().size() == 1);
  CHECK(space.mirrors().front().center == panel.center);
  std::size_t through = 0, checked = 0;
  space.ledger().scans().front().for_each([&](std::size_t, const iv::Beam& b, iv::BeamClass c) {
    const bool crosses = std::abs(b.end.y() * 0.5) < 0.1;           // the beam meets x = 0.3 at y = end.y / 2
    if (std::abs(std::abs(b.end.y() * 0.5) - 0.1) < 0.006) return;  // at the panel's edge: either
    ++checked;
    through += crosses ? 1 : 0;
    CHECK(c == (crosses ? iv::BeamClass::Suspect : iv::BeamClass::Trusted));
  });
  CHECK(through > 10);
  CHECK(checked > through + 10);
  CHECK(space.state(grid.geometry().key(iv::Point3(0.3, 0.0, 0.0))) == iv::ExplainedState::Occupied);
}
