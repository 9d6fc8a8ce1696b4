// The arm planner on explained free space (ArmPlannerParams::explained), on hand-built beams (no
// simulator): beams without a return from above the workcell cross the upper half of the sphere of
// views, so the plain map calls that space free while the explained evidence leaves it
// unexplained. Every sweep the explained planner accepts keeps the safety contract, checked by
// brute force over every pose of the sweep; the plain planner accepts sweeps that break it; the
// refusals are counted; the result does not depend on the thread count; planning without
// observe() is refused.
#include <intervox/explain/explained_space.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <vector>

namespace iv = intervox;

namespace {

const iv::Bounds kArmExplWorkcell{{0, 0, 0}, {1.5, 1.5, 1.5}};

iv::ArmPlannerParams arm_expl_params(bool explained, unsigned threads) {
  iv::ArmPlannerParams p;  // defaults: the ring part of the workcell, sphere of 0.45 m
  p.candidates = 40;
  p.profiles = 5;  // 5 cm apart, below the 6 cm margin: every pose of a sweep is checked
  p.threads = threads;
  p.seed = 3;
  p.explained.enabled = explained;
  return p;
}

/// Beams without a return from 0.85 m above the sphere's centre, fanning down over the upper
/// half of the sphere of views (to the planner's max range of 1 m), and returns from the sides
/// onto the object region (trusted hits).
std::vector<iv::Beam> arm_expl_beams() {
  std::vector<iv::Beam> beams;
  const iv::Point3 top(0.75, 0.75, 1.62);
  for (double dx = -0.6; dx <= 0.6; dx += 0.02)
    for (double dy = -0.6; dy <= 0.6; dy += 0.02) beams.push_back({top, top + iv::Point3(dx, dy, -1.0), false});
  for (double a = 0; a < 6.28; a += 0.05) {
    const iv::Point3 o(0.75 + 0.5 * std::cos(a), 0.75 + 0.5 * std::sin(a), 0.78);
    beams.push_back({o, iv::Point3(0.75 + 0.08 * std::cos(a), 0.75 + 0.08 * std::sin(a), 0.77), true});
  }
  return beams;
}

/// True if a voxel within the margin of a striper or flange pose of the sweep around \p view is
/// explained occupied or unexplained in \p space (brute force over every pose).
bool arm_expl_breaks_contract(const iv::ArmPlanner& planner, const iv::ExplainedSpace& space, const iv::GridGeometry& g,
                              const iv::Pose& view) {
  const double m = planner.params().collision_margin;
  const std::vector<iv::Pose> sensor = planner.sweep(view), body = planner.body_path(view);
  for (std::size_t k = 0; k < sensor.size(); ++k)
    for (const iv::Point3& p : {iv::Point3(sensor[k].translation()), iv::Point3(body[k].translation())}) {
      const iv::Key lo = g.key(p - iv::Point3::Constant(m)), hi = g.key(p + iv::Point3::Constant(m));
      for (std::int32_t z = lo.z; z <= hi.z; ++z)
        for (std::int32_t y = lo.y; y <= hi.y; ++y)
          for (std::int32_t x = lo.x; x <= hi.x; ++x) {
            const iv::Key key{x, y, z};
            if ((g.center(key) - p).norm() > m) continue;
            const iv::ExplainedState s = space.state(key);
            if (s == iv::ExplainedState::Occupied || s == iv::ExplainedState::Unexplained) return true;
          }
    }
  return false;
}

/// The planner's map of \p grid with \p beams inserted after the initial view, and the plan after them.
template <class Grid>
struct ArmExplPlan {
  iv::ExplainedMap<Grid> map;
  iv::ArmPlan plan;
};
template <class Grid>
ArmExplPlan<Grid> arm_expl_plan(Grid grid, iv::ArmPlanner& planner, const std::vector<iv::Beam>& beams) {
  iv::ExplainedMap<Grid> map = planner.make_map(std::move(grid));
  planner.plan(map);  // the initial view, planned before any measurement
  map.insert(std::span<const iv::Beam>(beams));
  iv::ArmPlan r = planner.plan(map);
  return {std::move(map), std::move(r)};
}

}  // namespace

TEMPLATE_TEST_CASE("the explained arm planner accepts no sweep near space only beams without a return crossed",
                   "[plan][arm][explained]", INTERVOX_TEST_GRIDS) {
  const std::vector<iv::Beam> beams = arm_expl_beams();
  iv::ArmPlanner planner(iv::SensorRig::arm(), arm_expl_params(true, 1));
  const ArmExplPlan<TestType> with =
      arm_expl_plan(test::make_grid_for<TestType>(0.02, kArmExplWorkcell), planner, beams);
  const iv::ArmPlan& r = with.plan;
  const auto& grid = with.map.grid();
  REQUIRE(with.map.explained());
  const iv::ExplainedSpace& space = *with.map.explained();

  // The contract, by brute force, for every accepted candidate.
  for (const iv::Pose& v : r.candidates) CHECK_FALSE(arm_expl_breaks_contract(planner, space, grid.geometry(), v));
  CHECK(r.refused[static_cast<std::size_t>(iv::SweepRefusal::Unexplained)] > 0);
  CHECK(r.sampled == r.candidates.size() + std::accumulate(r.refused.begin(), r.refused.end(), std::size_t{0}));

  // The plain planner, same seed: it accepts sweeps that break the contract, refusing none for it.
  iv::ArmPlanner plain(iv::SensorRig::arm(), arm_expl_params(false, 1));
  const ArmExplPlan<TestType> without =
      arm_expl_plan(test::make_grid_for<TestType>(0.02, kArmExplWorkcell), plain, beams);
  const iv::ArmPlan& q = without.plan;
  CHECK_FALSE(without.map.explained());
  CHECK(q.refused[static_cast<std::size_t>(iv::SweepRefusal::Unexplained)] == 0);
  CHECK(q.sampled == q.candidates.size() + std::accumulate(q.refused.begin(), q.refused.end(), std::size_t{0}));
  std::size_t breaking = 0;
  for (const iv::Pose& v : q.candidates) breaking += arm_expl_breaks_contract(plain, space, grid.geometry(), v);
  CHECK(breaking > 0);
  CHECK(q.candidates.size() > r.candidates.size());
}

TEST_CASE("the explained arm planner gives the same plan on any number of threads and refuses a plain grid",
          "[plan][arm][explained][threaded]") {
  const std::vector<iv::Beam> beams = arm_expl_beams();
  test::ThreadCap cap(2);
  iv::ArmPlanner p1(iv::SensorRig::arm(), arm_expl_params(true, 1)), p2(iv::SensorRig::arm(), arm_expl_params(true, 2));
  const iv::ArmPlan a = arm_expl_plan(test::make_grid_for<test::MeanDense>(0.02, kArmExplWorkcell), p1, beams).plan;
  const iv::ArmPlan b = arm_expl_plan(test::make_grid_for<test::MeanDense>(0.02, kArmExplWorkcell), p2, beams).plan;
  REQUIRE(a.candidates.size() == b.candidates.size());
  CHECK(a.selected == b.selected);
  CHECK(a.refused == b.refused);
  CHECK(a.view.matrix() == b.view.matrix());
  for (std::size_t i = 0; i < a.gains.size(); ++i) CHECK(a.gains[i].gain == b.gains[i].gain);

  test::MeanDense g3 = test::make_grid_for<test::MeanDense>(0.02, kArmExplWorkcell);
  iv::ArmPlanner p3(iv::SensorRig::arm(), arm_expl_params(true, 1));
  CHECK_THROWS_WITH(p3.plan(g3), Catch::Contains("ExplainedMap"));  // it reads a map's evidence, not a grid's
  iv::ArmPlannerParams bad = arm_expl_params(true, 1);
  bad.explained.explain.crossing_tolerance = -1.0;
  CHECK_THROWS_AS(iv::ArmPlanner(iv::SensorRig::arm(), bad), iv::InvalidArgument);
}
