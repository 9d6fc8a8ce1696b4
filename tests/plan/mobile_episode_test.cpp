// End-to-end mobile exploration of the ideal lab room (coarse voxels, subsampled gain rays): the
// planner decides, the runner drives its path and senses with the simulator.
#include <catch2/catch.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/source.hpp>

#include <cmath>
#include <optional>

namespace iv = intervox;

namespace {
const iv::Bounds kRoomFloor{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};

// Grid configurations: unbounded sparse, and sparse bounded to the room.
struct SparseBayes {
  using Grid = iv::BayesGrid;
  static std::optional<iv::Bounds> bounds() { return std::nullopt; }
};
struct SparseInterval {
  using Grid = iv::IntervalGrid;
  static std::optional<iv::Bounds> bounds() { return std::nullopt; }
};
struct BoundedSparseInterval {
  using Grid = iv::IntervalGrid;
  static std::optional<iv::Bounds> bounds() { return iv::Bounds{{-0.5, -0.5, -0.5}, {8.5, 6.5, 3.0}}; }
};

template <class Config>
struct MobileRun {
  using Grid = typename Config::Grid;
  iv::sim::LabRoom lab = iv::sim::make_lab_room();
  Grid grid{iv::GridGeometry(0.1), Config::bounds()};
  iv::MobilePlanner planner;
  iv::Episode<Grid, iv::MobilePlanner, iv::sim::SimulatedRig> episode;
  explicit MobileRun(std::uint64_t seed, unsigned threads = 2, std::optional<iv::Bounds> region = kRoomFloor)
      : planner(iv::SensorRig::mobile_base(), params(seed, threads, region)),
        episode(grid, planner, iv::sim::SimulatedRig(lab.scene, iv::SensorRig::mobile_base(), seed), start()) {}
  iv::Pose start() const { return iv::planar_pose(lab.start, 0.0); }
  static iv::MobilePlannerParams params(std::uint64_t seed, unsigned threads, std::optional<iv::Bounds> region) {
    iv::MobilePlannerParams p;
    p.region = region;
    p.seed = seed;
    p.threads = threads;
    p.max_steps = 25;
    return p;
  }
  iv::FloorCoverage floor() const {
    return iv::floor_coverage(grid, lab.scene, kRoomFloor, planner.params().map, start().translation());
  }
};
}  // namespace

TEMPLATE_TEST_CASE("an episode in the ideal lab room ends with at least 95% of the reachable free floor known",
                   "[plan][episode][slow]", SparseBayes, SparseInterval, BoundedSparseInterval) {
  // Seed 7 once trapped the interval robot in the maybe-collision space of its cameras' blind zone
  // (fixed by the escape zone of ExplorationMap).
  MobileRun<TestType> e(7);
  const iv::Termination t = e.episode.run();
  INFO("termination: " << iv::to_string(t) << " after " << e.planner.steps() << " steps");
  CHECK(t != iv::Termination::Budget);
  CHECK(t != iv::Termination::Blocked);
  const iv::FloorCoverage f = e.floor();
  INFO("reachable area known " << f.known << " of " << f.area << " m2");
  CHECK(f.known >= 0.95);
  CHECK(e.planner.steps() >= 2);
  for (const auto& s : e.episode.steps())
    if (s.plan.selected) CHECK(s.plan.relative_gain >= e.planner.params().min_relative_gain);
  // The robot drove its paths through known free floor: no pose of the trajectory lies within
  // the planner's 0.36 m robot radius of an obstacle. Under the thesis' map rules (whole start
  // columns free within 1 m, voxels with hits but not yet occupied unknown) seed 7 met the island
  // desk's edge at this radius with interval-mean (3 poses; docs/planning.md, "Seed 7 and the
  // island desk"); the library's start rule and hits_block keep it off.
  CHECK(iv::count_collisions(e.lab.scene, e.grid.geometry(), e.episode.trajectory(),
                             e.planner.params().map.robot_radius, 0.2, 0.8) == 0);
}

TEST_CASE("two episodes with the same seed give identical results, whatever the thread count",
          "[plan][episode][threaded][slow]") {
  MobileRun<SparseInterval> a(3, 1), b(3, 2);
  for (int i = 0; i < 4; ++i) {
    const auto& ra = a.episode.step();
    const auto& rb = b.episode.step();
    CHECK(ra.pose.matrix() == rb.pose.matrix());
    CHECK(ra.plan.frontier == rb.plan.frontier);
    REQUIRE(ra.plan.gains.size() == rb.plan.gains.size());
    for (std::size_t k = 0; k < ra.plan.gains.size(); ++k) CHECK(ra.plan.gains[k].gain == rb.plan.gains[k].gain);
  }
  CHECK(a.grid.counts().free == b.grid.counts().free);
  CHECK(a.grid.counts().occupied == b.grid.counts().occupied);
}

TEST_CASE("the mobile planner returns a drivable path over reachable cells from the robot to the view",
          "[plan][episode]") {
  MobileRun<SparseBayes> e(5);
  const iv::Pose before_look_around = e.episode.pose();
  const auto& first = e.episode.step();
  CHECK(first.plan.reason == iv::ViewReason::Initial);
  CHECK(first.plan.path.empty());
  CHECK(first.plan.scans.size() == 4);
  CHECK(first.pose.translation() == before_look_around.translation());
  int driven = 0;
  for (int i = 0; i < 4; ++i) {
    const iv::Pose from = e.episode.pose();
    const auto& s = e.episode.step();
    const iv::MobilePlan& p = s.plan;
    if (p.termination != iv::Termination::Running) break;
    CHECK(p.reason == iv::ViewReason::Frontier);
    REQUIRE(p.map);
    REQUIRE(p.path.size() >= 2);
    CHECK(p.path.front().matrix() == from.matrix());
    CHECK(p.path.back().matrix() == p.view.matrix());
    CHECK(p.scans.front().matrix() == p.view.matrix());
    const double res = e.grid.resolution();
    double length = 0;
    for (std::size_t k = 1; k < p.path.size(); ++k) {
      const double step = (p.path[k].translation() - p.path[k - 1].translation()).norm();
      // Neighbouring cell centres (from the start, which need not be a centre, half a cell more).
      CHECK(step <= 1.5 * std::sqrt(2.0) * res + 1e-9);
      length += step;
      const iv::Cell2 c = iv::MobilePlanner::robot_cell(e.grid.geometry(), p.path[k], p.region);
      CHECK(p.map->reachable(c));
    }
    CHECK(length == Catch::Detail::Approx(p.path_length).margin(1e-9));
    CHECK(s.pose.translation() == p.view.translation());  // the robot ends at the view, turned by its scans
    ++driven;
  }
  CHECK(driven >= 2);
  // The trajectory holds every pose driven through, so the robot did not teleport.
  const auto& t = e.episode.trajectory();
  for (std::size_t k = 1; k < t.size(); ++k)
    CHECK((t[k].translation() - t[k - 1].translation()).norm() <= 1.5 * std::sqrt(2.0) * e.grid.resolution() + 1e-9);
  CHECK(e.episode.distance_driven() > 1.0);
}

TEST_CASE("without a region the mobile planner derives one from the map and still explores the room",
          "[plan][episode][slow]") {
  MobileRun<SparseBayes> e(7, 2, std::nullopt);
  e.episode.step();  // the look-around
  const iv::Pose pose = e.episode.pose();
  const iv::Bounds r = e.planner.region_for(e.grid, pose);
  CHECK(r.min.z() == Catch::Detail::Approx(pose.translation().z() + 0.2));
  CHECK(r.max.z() == Catch::Detail::Approx(pose.translation().z() + 0.8));
  std::size_t outside = 0;
  e.grid.for_each_observed([&](const iv::Key& k, const auto&) {
    const iv::Point3 c = e.grid.center(k);
    if (c.x() < r.min.x() || c.y() < r.min.y() || c.x() > r.max.x() || c.y() > r.max.y()) ++outside;
  });
  CHECK(outside == 0);
  const iv::Termination t = e.episode.run();
  INFO("termination: " << iv::to_string(t) << " after " << e.planner.steps() << " steps");
  CHECK(t != iv::Termination::Blocked);
  CHECK(e.floor().known >= 0.9);
}

TEST_CASE("a relative gain threshold above any view ends the episode after the look-around", "[plan][episode]") {
  iv::sim::LabRoom lab = iv::sim::make_lab_room();
  iv::BayesGrid grid(0.1);
  iv::MobilePlannerParams p;
  p.region = kRoomFloor;
  p.min_relative_gain = 1.01;  // no view gains more than it would in an unobserved world
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  iv::Episode episode(grid, planner, iv::sim::SimulatedRig(lab.scene, iv::SensorRig::mobile_base(), 1),
                      iv::planar_pose(lab.start, 0.0));
  CHECK(episode.run() == iv::Termination::Explored);
  CHECK(planner.steps() == 1);
  CHECK(episode.steps().back().plan.considered > 0);
}

TEST_CASE("bad mobile planner input throws", "[plan][episode]") {
  auto throws_with = [](auto&& change) {
    iv::MobilePlannerParams p;
    change(p);
    CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), p), iv::InvalidArgument);
  };
  throws_with([](iv::MobilePlannerParams& p) { p.region = iv::Bounds{{1, 0, 0}, {0, 1, 1}}; });
  throws_with([](iv::MobilePlannerParams& p) { p.gain_stride = 0; });
  throws_with([](iv::MobilePlannerParams& p) { p.min_relative_gain = NAN; });
  throws_with([](iv::MobilePlannerParams& p) { p.floor_clearance = 1.0; });
  throws_with([](iv::MobilePlannerParams& p) { p.start_free_radius = -1; });
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig{}), iv::InvalidArgument);
  iv::MobilePlanner planner;
  iv::BayesGrid grid(0.1);
  iv::Pose nan_pose = iv::Pose::Identity();
  nan_pose.translation().x() = NAN;
  CHECK_THROWS_AS(planner.plan(grid, nan_pose), iv::InvalidArgument);
}

TEST_CASE("a trajectory pose whose robot cylinder reaches into a wall counts as a collision", "[plan][episode]") {
  const iv::sim::LabRoom lab = iv::sim::make_lab_room();
  const iv::GridGeometry g(0.05);
  const iv::Pose clear = iv::planar_pose(lab.start, 0.0);
  const iv::Pose at_wall = iv::planar_pose(iv::Point3(0.2, 3.0, 0.0), 0.0);  // the west wall is at x = 0
  CHECK(iv::count_collisions(lab.scene, g, {clear}, 0.36, 0.2, 0.8) == 0);
  CHECK(iv::count_collisions(lab.scene, g, {at_wall}, 0.36, 0.2, 0.8) == 1);
  CHECK(iv::count_collisions(lab.scene, g, {clear, at_wall, at_wall}, 0.36, 0.2, 0.8) == 2);
  CHECK(iv::count_collisions(lab.scene, g, {at_wall}, 0.1, 0.2, 0.8) == 0);  // a thinner robot fits
  CHECK_THROWS_AS(iv::count_collisions(lab.scene, g, {clear}, -1.0, 0.2, 0.8), iv::InvalidArgument);
}

TEST_CASE("a path through a thin obstacle collides even when both its poses are clear", "[plan][eval]") {
  // barrier_2 is [3.0, 3.1] x [1.9, 3.3], 0.4 m high: poses 0.5 m either side of it are clear, the
  // straight segment between them crosses it.
  iv::sim::Scene s;
  s.add_box({{3.0, 1.9, 0.0}, {3.1, 3.3, 0.4}}, {}, "barrier");
  const iv::GridGeometry g(0.05);
  const iv::Pose west = iv::planar_pose(iv::Point3(2.4, 2.6, 0.0), 0.0),
                 east = iv::planar_pose(iv::Point3(3.7, 2.6, 0.0), 0.0);
  const iv::Pose north = iv::planar_pose(iv::Point3(2.4, 3.9, 0.0), 0.0);
  const auto across = iv::count_path_collisions(s, g, {west, east}, 0.2, 0.0, 0.8);
  CHECK(across.poses == 0);
  CHECK(across.segments == 1);
  const auto around = iv::count_path_collisions(s, g, {west, north}, 0.2, 0.0, 0.8);  // past its end: clear
  CHECK(around.poses == 0);
  CHECK(around.segments == 0);
  const auto over = iv::count_path_collisions(s, g, {west, east}, 0.2, 0.5, 0.8);  // a robot body above 0.4 m passes
  CHECK(over.segments == 0);
  CHECK(iv::count_path_collisions(s, g, {west}, 0.2, 0.0, 0.8).segments == 0);
  CHECK_THROWS_AS(iv::count_path_collisions(s, g, {west, east}, std::nan(""), 0.0, 0.8), iv::InvalidArgument);
}

TEST_CASE("collisions are attributed to the objects the robot's footprint meets", "[plan][eval]") {
  // Two boxes 1 m apart and one far away. The robot stands 0.2 m from the left box, drives round
  // to the middle of the gap (0.5 m from each box) and leaves the gap to the north.
  iv::sim::Scene s;
  const iv::sim::ObjectId left = s.add_box({{0.0, 0.0, 0.0}, {0.5, 0.5, 1.0}}, {}, "left");
  const iv::sim::ObjectId right = s.add_box({{1.5, 0.0, 0.0}, {2.0, 0.5, 1.0}}, {}, "right");
  s.add_box({{5.0, 5.0, 0.0}, {5.5, 5.5, 1.0}}, {}, "far");
  const iv::GridGeometry g(0.05);
  const auto at = [](double x, double y) { return iv::planar_pose(iv::Point3(x, y, 0.0), 0.0); };
  const std::vector<iv::Pose> path{at(0.7, 0.25), at(1.0, -1.0), at(1.0, 0.25), at(1.0, 3.0)};
  // Radius 0.3: only the first pose meets the left box, and with it the first segment.
  const auto narrow = iv::collisions_by_object(s, g, path, 0.3, 0.2, 0.8);
  REQUIRE(narrow.size() == 1);
  CHECK(narrow[0].object == left);
  CHECK(narrow[0].name == "left");
  CHECK(narrow[0].poses == 1);
  CHECK(narrow[0].segments == 1);
  // Radius 0.6: the pose in the gap meets both boxes; so do the segments into and out of it.
  const auto wide = iv::collisions_by_object(s, g, path, 0.6, 0.2, 0.8);
  REQUIRE(wide.size() == 2);
  CHECK(wide[0].object == left);
  CHECK(wide[0].poses == 2);
  CHECK(wide[0].segments == 3);
  CHECK(wide[1].object == right);
  CHECK(wide[1].name == "right");
  CHECK(wide[1].poses == 1);
  CHECK(wide[1].segments == 2);
  // count_path_collisions counts each pose once, whatever it meets.
  const auto total = iv::count_path_collisions(s, g, path, 0.6, 0.2, 0.8);
  CHECK(total.poses == 2);
  CHECK(total.segments == 3);
  CHECK(iv::collisions_by_object(s, g, {at(3.0, 3.0)}, 0.6, 0.2, 0.8).empty());
  CHECK_THROWS_AS(iv::collisions_by_object(s, g, path, 0.6, 0.9, 0.8), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::collisions_by_object(s, g, {at(std::nan(""), 0.0)}, 0.6, 0.2, 0.8), iv::InvalidArgument);
}
