// Conflict-aware arm modelling on a hand-built grid (no simulator): a block on the table with a
// planted conflict patch two voxels in front of its +y face. The planner must aim views at the
// patch from inside the cone around the face's normal, keep its sweeps clear of the patch by the
// safety margin, give the patch up after a bounded number of views, and decide the same for any
// thread count.
#include <catch2/catch.hpp>
#include <intervox/analysis/conflicts.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
// GCC 12 under ASan/UBSan reports the DepthCamera alternative of the variant that
// SensorRig::arm() validates (it holds a LaserStriper) as "maybe used uninitialized" when the
// call is inlined here: a false positive of its flow analysis (every field has an initialiser).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <intervox/plan/arm_planner.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

namespace iv = intervox;

namespace {
constexpr std::string_view kConflictSequence = "HHHHHHMMMMMMHH";  // stays [0.55, 0.55] when repeated
constexpr std::string_view kOccupiedSequence = "HHHHHHHHHH";

void feed(iv::DenseIntervalGrid& g, const iv::Key& k, std::string_view seq) {
  for (const char c : seq) g.update(k, c == 'H' ? iv::Observation::Hit : iv::Observation::Miss);
}

struct Block {
  iv::DenseIntervalGrid grid{0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}};
  std::vector<iv::Key> patch;  // the planted conflict voxels
  Block() {
    const iv::GridGeometry& g = grid.geometry();
    const iv::Key lo = g.key({0.725, 0.725, 0.755}), hi = g.key({0.775, 0.775, 0.785});
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) feed(grid, {x, y, z}, kOccupiedSequence);
    // Two voxels in front of the +y face: 4 x 2 voxels, beyond the surface-fringe distance.
    for (int z = lo.z + 1; z <= lo.z + 2; ++z)
      for (int x = lo.x + 1; x <= lo.x + 4; ++x) patch.push_back({x, hi.y + 2, z});
    for (const iv::Key& k : patch) feed(grid, k, kConflictSequence);
  }
  iv::Point3 centroid() const {
    iv::Point3 c = iv::Point3::Zero();
    for (const iv::Key& k : patch) c += grid.center(k);
    return c / double(patch.size());
  }
};

iv::ArmPlannerParams params(bool aware, unsigned threads) {
  iv::ArmPlannerParams p;  // the object region and sphere of the built-in workcell's part
  p.conflicts.enabled = aware;
  p.threads = threads;
  p.candidates = 12;
  p.max_views = 20;
  p.min_relative_gain = 0;  // only the conflict rules and the budget end the episode
  return p;
}

double angle(const iv::Point3& a, const iv::Point3& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0));
}

// The smallest distance of any striper or flange pose of the sweep around `view` to `points`.
double clearance(const iv::ArmPlanner& planner, const iv::Pose& view, const std::vector<iv::Point3>& points) {
  double d = 1e9;
  const std::vector<iv::Pose> sensor = planner.sweep(view), body = planner.body_path(view);
  for (std::size_t k = 0; k < sensor.size(); ++k)
    for (const iv::Point3& p : {iv::Point3(sensor[k].translation()), iv::Point3(body[k].translation())})
      for (const iv::Point3& q : points) d = std::min(d, (p - q).norm());
  return d;
}
}  // namespace

TEST_CASE("the conflict-aware arm aims at a conflict patch from inside its normal cone, then gives it up",
          "[plan][arm][conflicts]") {
  const Block b;
  const iv::ConflictReport rep = iv::detect_conflicts(b.grid);
  REQUIRE(rep.regions.size() == 1);
  REQUIRE(rep.regions[0].size() == b.patch.size());
  iv::ArmPlanner planner(iv::SensorRig::arm(), params(true, 2));
  const iv::ArmPlannerParams& p = planner.params();
  const iv::Point3 c = b.centroid();
  // The face's normal is +y (horizontal); the cone's axis is raised to the lowest elevation.
  const iv::Point3 axis(0.0, std::cos(p.min_elevation), std::sin(p.min_elevation));
  REQUIRE(planner.plan(b.grid).reason == iv::ViewReason::Initial);
  int conflict_views = 0;
  bool gave_up = false;
  for (int step = 1; step < p.max_views && !gave_up; ++step) {
    const iv::ArmPlan r = planner.plan(b.grid);
    REQUIRE(r.termination == iv::Termination::Running);
    REQUIRE(r.regions.size() == 1);
    if (r.reason == iv::ViewReason::Conflict) {
      ++conflict_views;
      REQUIRE(r.conflict_region == std::size_t{0});
      const iv::Point3 eye = r.view.translation();
      CHECK((eye - c).norm() == Approx(p.sphere_radius).margin(1e-9));
      CHECK(angle(eye - c, axis) <= p.normal_cone + 1e-9);
      CHECK(angle(r.view.linear().col(2), c - eye) < 1e-6);  // the striper looks at the centroid
    } else {
      REQUIRE(r.reason == iv::ViewReason::Gain);
      CHECK(r.regions[0].unresolvable);
      gave_up = true;
    }
  }
  CHECK(conflict_views >= 1);
  CHECK(conflict_views <= p.conflicts.max_region_views);
  CHECK(gave_up);
}

TEST_CASE("the arm's safety margin keeps every sweep clear of conflict voxels", "[plan][arm][conflicts]") {
  const Block b;
  std::vector<iv::Point3> conflict;
  for (const iv::Key& k : b.patch) conflict.push_back(b.grid.center(k));
  // A margin wide enough to reach the sphere of views: the plain planner accepts sweeps inside it.
  auto with_margin = [](bool aware) {
    iv::ArmPlannerParams p = params(aware, 1);
    p.conflicts.safety_margin = 0.40;
    p.candidates = 40;
    return p;
  };
  const double margin = with_margin(true).collision_margin + with_margin(true).conflicts.safety_margin;
  std::size_t plain_inside = 0, aware_considered = 0;
  for (const bool aware : {false, true}) {
    iv::ArmPlanner planner(iv::SensorRig::arm(), with_margin(aware));
    for (int step = 0; step < 6; ++step) {
      const iv::ArmPlan r = planner.plan(b.grid);
      if (r.termination != iv::Termination::Running) break;
      for (const iv::Pose& v : r.candidates) {
        const double d = clearance(planner, v, conflict);
        if (aware) {
          ++aware_considered;
          CHECK(d > margin);
        } else if (d <= margin) {
          ++plain_inside;
        }
      }
    }
  }
  CHECK(aware_considered > 0);
  CHECK(plain_inside > 0);  // the margin matters: without it, sweeps come that close
}

TEST_CASE("conflict-aware arm plans are the same for any thread count", "[plan][arm][conflicts][threaded][slow]") {
  const Block b;
  iv::ArmPlanner one(iv::SensorRig::arm(), params(true, 1)), three(iv::SensorRig::arm(), params(true, 3));
  for (int step = 0; step < 8; ++step) {
    const iv::ArmPlan a = one.plan(b.grid), c = three.plan(b.grid);
    REQUIRE(a.reason == c.reason);
    REQUIRE(a.termination == c.termination);
    REQUIRE(a.view.isApprox(c.view, 0.0));
    REQUIRE(a.gain == c.gain);
  }
}

TEST_CASE("conflict-aware arm modelling refuses a Bayes grid and a bad cone", "[plan][arm][conflicts]") {
  iv::DenseBayesGrid bayes(0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}});
  iv::ArmPlanner planner(iv::SensorRig::arm(), params(true, 1));
  CHECK_THROWS_AS(planner.plan(bayes), iv::InvalidArgument);
  iv::ArmPlannerParams p = params(true, 1);
  p.normal_cone = 0;
  CHECK_THROWS_AS(iv::ArmPlanner(iv::SensorRig::arm(), p), iv::InvalidArgument);
  p.normal_cone = 2.0;
  CHECK_THROWS_AS(iv::ArmPlanner(iv::SensorRig::arm(), p), iv::InvalidArgument);
}
